//! Binary voxel samples (u8 … f64, either byte order) streamed from a reader
//! into `f32`, shared by the NIfTI and raw readers.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The stored type of one voxel sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SampleType {
    /// Unsigned 8-bit.
    U8,
    /// Signed 8-bit.
    I8,
    /// Unsigned 16-bit.
    U16,
    /// Signed 16-bit.
    I16,
    /// Unsigned 32-bit.
    U32,
    /// Signed 32-bit.
    I32,
    /// Unsigned 64-bit.
    U64,
    /// Signed 64-bit.
    I64,
    /// IEEE 754 binary32.
    F32,
    /// IEEE 754 binary64.
    F64,
}

impl SampleType {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::U64 | SampleType::I64 | SampleType::F64 => 8,
        }
    }

    /// Short name (`u8`, `i16`, `f32`, …), as a data-gen sidecar's `dtype`.
    pub fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "u8",
            SampleType::I8 => "i8",
            SampleType::U16 => "u16",
            SampleType::I16 => "i16",
            SampleType::U32 => "u32",
            SampleType::I32 => "i32",
            SampleType::U64 => "u64",
            SampleType::I64 => "i64",
            SampleType::F32 => "f32",
            SampleType::F64 => "f64",
        }
    }

    /// The type named `name`: `u8`/`uint8`, …, `f32`/`float32`/`float`,
    /// `f64`/`float64`/`double` (case-insensitive).
    pub fn from_name(name: &str) -> Option<SampleType> {
        let t = match name.trim().to_ascii_lowercase().as_str() {
            "u8" | "uint8" => SampleType::U8,
            "i8" | "int8" => SampleType::I8,
            "u16" | "uint16" => SampleType::U16,
            "i16" | "int16" => SampleType::I16,
            "u32" | "uint32" => SampleType::U32,
            "i32" | "int32" => SampleType::I32,
            "u64" | "uint64" => SampleType::U64,
            "i64" | "int64" => SampleType::I64,
            "f32" | "float32" | "float" => SampleType::F32,
            "f64" | "float64" | "double" => SampleType::F64,
            _ => return None,
        };
        Some(t)
    }
}

/// Appends the samples in `bytes` (a whole number of samples) to `out` as f32.
fn convert_into(bytes: &[u8], ty: SampleType, big_endian: bool, out: &mut Vec<f32>) {
    macro_rules! conv {
        ($t:ty, $n:expr) => {
            out.extend(bytes.chunks_exact($n).map(|c| {
                let mut a = [0u8; $n];
                a.copy_from_slice(c);
                (if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f32
            }))
        };
    }
    match ty {
        SampleType::U8 => out.extend(bytes.iter().map(|&b| f32::from(b))),
        SampleType::I8 => out.extend(bytes.iter().map(|&b| f32::from(b as i8))),
        SampleType::U16 => conv!(u16, 2),
        SampleType::I16 => conv!(i16, 2),
        SampleType::U32 => conv!(u32, 4),
        SampleType::I32 => conv!(i32, 4),
        SampleType::U64 => conv!(u64, 8),
        SampleType::I64 => conv!(i64, 8),
        SampleType::F32 => conv!(f32, 4),
        SampleType::F64 => conv!(f64, 8),
    }
}

/// Reads exactly `count` samples of `ty` from `reader` (streamed in 1 MiB
/// chunks, so a compressed input is never held uncompressed in full) and
/// returns them as f32. A short input is the error "truncated: … needs N
/// bytes …, the file has only M", naming `path`.
pub(crate) fn read_samples(
    reader: &mut dyn Read,
    count: usize,
    ty: SampleType,
    big_endian: bool,
    path: &Path,
) -> Result<Vec<f32>> {
    let need = count
        .checked_mul(ty.size())
        .ok_or_else(|| Error::parse(path, 0, "the voxel data size overflows"))?;
    crate::memory::check_memory(
        &format!("reading {count} voxels of {} as f32", path.display()),
        crate::memory::bytes_of(count as u64, 4),
    )?;
    let mut out = Vec::new();
    crate::allocator::try_reserve_exact(&mut out, count).map_err(|_| {
        Error::parse(
            path,
            0,
            format!("cannot allocate {count} voxels ({need} bytes)"),
        )
    })?;
    let chunk = (1 << 20) / 8 * 8;
    let mut buf = vec![0u8; chunk.min(need.max(1))];
    let mut got = 0usize;
    while got < need {
        let want = buf.len().min(need - got);
        let mut filled = 0;
        while filled < want {
            let n = reader
                .read(&mut buf[filled..want])
                .map_err(|e| Error::parse(path, 0, format!("reading the voxel data: {e}")))?;
            if n == 0 {
                return Err(Error::parse(
                    path,
                    0,
                    format!(
                        "truncated: the voxel data needs {need} bytes ({count} {} samples), the file has only {}",
                        ty.name(),
                        got + filled
                    ),
                ));
            }
            filled += n;
        }
        convert_into(&buf[..want], ty, big_endian, &mut out);
        got += want;
    }
    Ok(out)
}

/// Reads and discards `n` bytes; `false` when the input ends first.
pub(crate) fn skip_bytes(reader: &mut dyn Read, n: u64, path: &Path) -> Result<bool> {
    let copied = std::io::copy(&mut reader.take(n), &mut std::io::sink())
        .map_err(|e| Error::parse(path, 0, format!("reading: {e}")))?;
    Ok(copied == n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_long_names_parse() {
        for t in [SampleType::U8, SampleType::I16, SampleType::F64] {
            assert_eq!(SampleType::from_name(t.name()), Some(t));
        }
        assert_eq!(SampleType::from_name("uint16"), Some(SampleType::U16));
        assert_eq!(SampleType::from_name("Float32"), Some(SampleType::F32));
        assert_eq!(SampleType::from_name("double"), Some(SampleType::F64));
        assert_eq!(SampleType::from_name("rgb"), None);
    }

    #[test]
    fn both_byte_orders_and_truncation() {
        let p = Path::new("t");
        let le: Vec<u8> = [-2i16, 300].iter().flat_map(|v| v.to_le_bytes()).collect();
        let be: Vec<u8> = [-2i16, 300].iter().flat_map(|v| v.to_be_bytes()).collect();
        let a = read_samples(&mut &le[..], 2, SampleType::I16, false, p).unwrap();
        let b = read_samples(&mut &be[..], 2, SampleType::I16, true, p).unwrap();
        assert_eq!(a, vec![-2.0, 300.0]);
        assert_eq!(a, b);
        let e = read_samples(&mut &le[..3], 2, SampleType::I16, false, p).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
    }
}

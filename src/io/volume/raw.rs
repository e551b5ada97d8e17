//! Raw volumes: headerless samples described by a JSON sidecar (data-gen's
//! `BASE.json`; see [`sidecar`](super::sidecar) for the fields). The data
//! file is `BASE.raw`, or the sidecar's first `files` entry when the
//! `.json` is given.

use std::io::BufReader;
use std::path::{Path, PathBuf};

use super::decoded::{Decoded, Placement};
use super::samples::{SampleType, read_samples, skip_bytes};
use super::sidecar::Sidecar;
use crate::error::{Error, Result};

/// Reads the raw volume at `path` (the `.raw` or its `.json`), described by `sidecar`.
pub(crate) fn read_raw(path: &Path, sidecar: Option<&Sidecar>) -> Result<Decoded> {
    let side = sidecar.ok_or_else(|| {
        Error::parse(
            path,
            0,
            "a raw volume needs a JSON header BASE.json with at least \"dims\" beside it",
        )
    })?;
    let data_path = data_file(path, side)?;
    let dtype = match &side.dtype {
        None => SampleType::F32,
        Some(name) => SampleType::from_name(name).ok_or_else(|| {
            Error::parse(
                &side.path,
                0,
                format!(
                    "dtype '{name}' is not one of u8, i8, u16, i16, u32, i32, u64, i64, f32, f64"
                ),
            )
        })?,
    };
    let big_endian = match side.byte_order.as_deref().map(str::to_ascii_lowercase) {
        None => false,
        Some(o) if o == "little" || o == "le" => false,
        Some(o) if o == "big" || o == "be" => true,
        Some(o) => {
            return Err(Error::parse(
                &side.path,
                0,
                format!("byte_order '{o}' is neither 'little' nor 'big'"),
            ));
        }
    };
    let file = crate::io::open_regular(&data_path)?;
    let count: usize = side.dims.iter().product();
    let need = (count as u64) * dtype.size() as u64 + side.header_bytes;
    let len = file.metadata().map_err(|e| Error::io(&data_path, e))?.len();
    if len != need {
        return Err(Error::parse(
            &data_path,
            0,
            format!(
                "{len} bytes, but {} header bytes + {:?} {} samples make {need}",
                side.header_bytes,
                side.dims,
                dtype.name()
            ),
        ));
    }
    let mut reader = BufReader::with_capacity(1 << 16, file);
    if !skip_bytes(&mut reader, side.header_bytes, &data_path)? {
        return Err(Error::parse(&data_path, 0, "shorter than header_bytes"));
    }
    let data = read_samples(&mut reader, count, dtype, big_endian, &data_path)?;
    Ok(Decoded {
        dims: side.dims,
        data,
        placement: Placement::Grid { spacing: None },
        source: format!(
            "raw {}, {}-endian, header {}",
            dtype.name(),
            if big_endian { "big" } else { "little" },
            side.path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        ),
        notes: Vec::new(),
        physical: false,
    })
}

/// The data file: `path` itself unless it is the `.json`, then the sidecar's
/// first `files` entry or `BASE.raw`. A `files` entry must be a plain file
/// name in the sidecar's directory: no directories, `..` or absolute paths.
fn data_file(path: &Path, side: &Sidecar) -> Result<PathBuf> {
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        return Ok(path.to_path_buf());
    }
    match side.files.first() {
        Some(f) => {
            let plain = Path::new(f)
                .file_name()
                .is_some_and(|name| name == std::ffi::OsStr::new(f.as_str()));
            if !plain || f == ".." || f == "." {
                return Err(Error::parse(
                    &side.path,
                    0,
                    format!("files entry {f:?} is not a file name in the sidecar's directory"),
                ));
            }
            Ok(side.path.with_file_name(f))
        }
        None => Ok(side.path.with_extension("raw")),
    }
}

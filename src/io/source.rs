//! The bytes of an input: a regular file read in one go within the memory
//! budget, gunzipped (with the budget as a cap) when it is gzip data, and
//! rejected when empty.

use std::borrow::Cow;
use std::fs::File;
use std::io::Read;
use std::path::Path;

use flate2::read::MultiGzDecoder;

use crate::error::{Error, Result};
use crate::memory::{check_memory, human_bytes, memory_budget};

/// The two bytes every gzip stream starts with.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Opens `path` if it is a regular file (symbolic links followed). A FIFO,
/// a device (`/dev/zero`), a socket or a directory is an error before it
/// is opened: opening a FIFO waits for a writer, and a device may never end.
pub(crate) fn open_regular(path: &Path) -> Result<File> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(Error::input(format!(
            "{}: not a regular file ({}); inputs must be files",
            path.display(),
            file_kind(&meta)
        )));
    }
    File::open(path).map_err(|e| Error::io(path, e))
}

/// What a non-regular file is, for the error.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a file"
    }
}

/// Reads the whole regular file at `path` (one buffered read; no text format
/// is split into lines until it is in memory), if its size fits the budget.
///
/// ```no_run
/// let bytes = subdyn::io::read_input("lattice.json")?;
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn read_input(path: impl AsRef<Path>) -> Result<Vec<u8>> {
    let path = path.as_ref();
    let file = open_regular(path)?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    check_memory(&format!("reading {}", path.display()), len)?;
    let mut out = Vec::with_capacity(len as usize);
    // A file that grows while read is cut at its size when opened.
    file.take(len)
        .read_to_end(&mut out)
        .map_err(|e| Error::io(path, e))?;
    Ok(out)
}

/// The uncompressed contents: `bytes` themselves, or their gunzipped form when
/// they start with the gzip magic number (whatever the file is called).
/// Inflating stops with an error past the memory budget; a bad CRC or a
/// missing trailer is an error. Empty contents (before or after
/// decompression) are an error "… is empty".
pub(crate) fn contents<'a>(bytes: &'a [u8], path: &Path) -> Result<Cow<'a, [u8]>> {
    if bytes.is_empty() {
        return Err(empty(path));
    }
    if !bytes.starts_with(&GZIP_MAGIC) {
        return Ok(Cow::Borrowed(bytes));
    }
    Ok(Cow::Owned(inflate(
        MultiGzDecoder::new(bytes),
        bytes.len(),
        path,
    )?))
}

/// Everything `decoder` inflates to, at most the memory budget.
fn inflate(decoder: impl Read, compressed: usize, path: &Path) -> Result<Vec<u8>> {
    let budget = memory_budget();
    let mut out = Vec::with_capacity((compressed as u64).saturating_mul(4).min(budget) as usize);
    decoder
        .take(budget.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| Error::parse(path, 0, format!("cannot decompress gzip data: {e}")))?;
    if out.len() as u64 > budget {
        return Err(Error::parse(
            path,
            0,
            format!(
                "the gzip data inflates to more than the memory budget of {} (--max-memory sets it)",
                human_bytes(budget)
            ),
        ));
    }
    if out.is_empty() {
        return Err(empty(path));
    }
    Ok(out)
}

/// The error for a file without contents.
fn empty(path: &Path) -> Error {
    Error::parse(path, 0, "the file is empty")
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::{Compression, write::GzEncoder};
    use std::io::Write;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut e = GzEncoder::new(Vec::new(), Compression::fast());
        e.write_all(data).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn a_bad_crc_or_a_missing_trailer_is_an_error() {
        let name = Path::new("x.ply.gz");
        let good = gzip(b"ply\nformat ascii 1.0\n");
        assert_eq!(&*contents(&good, name).unwrap(), b"ply\nformat ascii 1.0\n");
        let mut bad_crc = good.clone();
        let n = bad_crc.len();
        bad_crc[n - 8] ^= 1;
        assert!(contents(&bad_crc, name).is_err());
        assert!(contents(&good[..n - 8], name).is_err());
    }

    #[test]
    fn a_fifo_or_a_device_is_not_read() {
        let err = read_input("/dev/zero").unwrap_err().to_string();
        assert!(err.contains("not a regular file (a device)"), "{err}");
        let err = read_input("/").unwrap_err().to_string();
        assert!(err.contains("a directory"), "{err}");
    }
}

//! The bytes of an input: a whole file read in one go, gunzipped when it is
//! gzip data, and rejected when empty.

use std::borrow::Cow;
use std::io::Read;
use std::path::Path;

use flate2::read::MultiGzDecoder;

use crate::error::{Error, Result};

/// The two bytes every gzip stream starts with.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Reads the whole file at `path` (one buffered read; no text format is split
/// into lines until it is in memory).
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// The uncompressed contents: `bytes` themselves, or their gunzipped form when
/// they start with the gzip magic number (whatever the file is called).
/// Empty contents (before or after decompression) are an error "… is empty".
pub(crate) fn contents<'a>(bytes: &'a [u8], path: &Path) -> Result<Cow<'a, [u8]>> {
    if bytes.is_empty() {
        return Err(empty(path));
    }
    if !bytes.starts_with(&GZIP_MAGIC) {
        return Ok(Cow::Borrowed(bytes));
    }
    let mut out = Vec::with_capacity(bytes.len().saturating_mul(4));
    MultiGzDecoder::new(bytes)
        .read_to_end(&mut out)
        .map_err(|e| Error::parse(path, 0, format!("cannot decompress gzip data: {e}")))?;
    if out.is_empty() {
        return Err(empty(path));
    }
    Ok(Cow::Owned(out))
}

/// The error for a file without contents.
fn empty(path: &Path) -> Error {
    Error::parse(path, 0, "the file is empty")
}

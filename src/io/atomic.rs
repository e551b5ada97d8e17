//! `atomic_write`: write a file whole or not at all.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{Error, Result};

/// Distinguishes temporary files of concurrent writes from one process.
static SEQUENCE: AtomicUsize = AtomicUsize::new(0);

/// Writes a file through `write`, all or nothing.
///
/// The closure writes to a buffered temporary file in the target's directory
/// (`.name.tmp.<pid>.<n>`), which is then renamed over `path`. If the closure
/// fails, or creating, flushing or renaming fails, the temporary file is
/// removed and `path` is left as it was (absent, or the previous file whole).
/// The data is not fsync'ed.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("hello.txt");
/// subdyn::io::atomic_write(&path, |w| w.write_all(b"hello\n"))?;
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn atomic_write(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let temp = temp_path(path)?;
    let result = write_then_rename(&temp, path, write);
    if result.is_err() {
        // Best effort: the temporary file may not even exist.
        let _ = std::fs::remove_file(&temp);
    }
    result.map_err(|e| Error::io(path, e))
}

/// Creates `temp`, fills it through `write`, flushes it and renames it to `path`.
fn write_then_rename(
    temp: &Path,
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut out = BufWriter::with_capacity(1 << 16, File::create(temp)?);
    write(&mut out)?;
    out.into_inner().map_err(|e| e.into_error())?;
    std::fs::rename(temp, path)
}

/// `dir/.name.tmp.<pid>.<n>` beside `path`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| Error::Input(format!("{}: not a file name to write to", path.display())))?;
    let n = SEQUENCE.fetch_add(1, Ordering::Relaxed);
    let temp_name = format!(".{}.tmp.{}.{n}", name.to_string_lossy(), std::process::id());
    Ok(path.with_file_name(temp_name))
}

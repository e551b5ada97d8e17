//! `atomic_write`: write a file whole or not at all, through a temporary
//! file that this process registers, so that a run stopped by a signal can
//! remove it ([`remove_temporary_files`]) and an [`OutputBatch`] can hold it
//! back until the whole run has succeeded.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

use crate::error::{Error, Result};

#[cfg(doc)]
use super::OutputBatch;

/// Distinguishes temporary files of concurrent writes from one process.
static SEQUENCE: AtomicUsize = AtomicUsize::new(0);

/// What this process has on disk that is not an output yet.
#[derive(Default)]
pub(super) struct Registry {
    /// Temporary files that exist now (being written, or staged).
    pub live: Vec<PathBuf>,
    /// The open batch's `(temporary, target)` pairs (`None`: no batch).
    pub staged: Option<Vec<(PathBuf, PathBuf)>>,
    /// Directories the open batch created, outermost first.
    pub created_dirs: Vec<PathBuf>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    live: Vec::new(),
    staged: None,
    created_dirs: Vec::new(),
});

/// The registry, even if a thread panicked while holding it (its contents
/// are plain lists that stay valid).
pub(super) fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

/// Writes a file through `write`, all or nothing.
///
/// The closure writes to a buffered temporary file in the target's directory
/// (`.name.tmp.<pid>.<n>`, never one that exists already, so stale files of
/// a killed run are left alone), which is then renamed over `path` (or,
/// while an [`OutputBatch`] is open, kept until the batch commits). If the
/// closure fails, or creating, flushing or renaming fails, the temporary
/// file is removed and `path` is left as it was (absent, or the previous
/// file whole). The data is not fsync'ed.
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
    // Created under the registry's lock, so a signal's clean-up either sees
    // the file or runs before it exists.
    let (temp, file) = {
        let mut reg = registry();
        let (temp, file) = create_temp(path).map_err(|e| Error::io(path, e))?;
        reg.live.push(temp.clone());
        (temp, file)
    };
    let result = fill(file, write).and_then(|()| {
        let mut guard = registry();
        let reg = &mut *guard;
        match &mut reg.staged {
            Some(staged) => {
                // A second write of the same target replaces the first.
                if let Some(k) = staged.iter().position(|(_, p)| p == path) {
                    let (old, _) = staged.remove(k);
                    let _ = std::fs::remove_file(&old);
                    reg.live.retain(|t| *t != old);
                }
                staged.push((temp.clone(), path.to_path_buf()));
                Ok(())
            }
            None => {
                let renamed = std::fs::rename(&temp, path);
                reg.live.retain(|t| *t != temp);
                renamed
            }
        }
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
        registry().live.retain(|t| *t != temp);
    }
    result.map_err(|e| Error::io(path, e))
}

/// Fills `file` through `write` and flushes it.
fn fill(
    file: File,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut out = BufWriter::with_capacity(1 << 16, file);
    write(&mut out)?;
    out.into_inner().map_err(|e| e.into_error())?;
    Ok(())
}

/// Creates a new `dir/.name.tmp.<pid>.<n>` beside `path`, skipping names
/// that exist (left by a killed process with the same id).
fn create_temp(path: &Path) -> std::io::Result<(PathBuf, File)> {
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a file name to write to",
        )
    })?;
    loop {
        let n = SEQUENCE.fetch_add(1, Ordering::Relaxed);
        let temp_name = format!(".{}.tmp.{}.{n}", name.to_string_lossy(), std::process::id());
        let temp = path.with_file_name(temp_name);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((temp, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 1 << 20 => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Fails unless a file can be written at `path`: its directory exists and
/// takes a new file, and `path` is not a directory. Nothing is left behind
/// (a probe file is created and removed). For checking every output path
/// before a long run.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// use subdyn::io::check_writable;
/// assert!(check_writable(&dir.path().join("out.obj")).is_ok());
/// let err = check_writable(&dir.path().join("missing/out.obj")).unwrap_err();
/// assert!(err.to_string().contains("does not exist"));
/// assert!(check_writable(dir.path()).is_err());
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
/// ```
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(Error::input(format!(
            "{}: the directory {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    if path.is_dir() {
        return Err(Error::input(format!(
            "{}: is a directory, not a file name to write to",
            path.display()
        )));
    }
    let (temp, file) = create_temp(path).map_err(|e| {
        Error::input(format!(
            "{}: cannot create a file in {}: {e}",
            path.display(),
            dir.display()
        ))
    })?;
    drop(file);
    let _ = std::fs::remove_file(temp);
    Ok(())
}

/// Removes every temporary file this process has open or staged, and the
/// directories the open batch created, then keeps the registry locked so
/// that no new temporary file appears: for a signal handler that ends the
/// process right after.
pub fn remove_temporary_files() {
    let mut reg = registry();
    for temp in reg.live.drain(..) {
        let _ = std::fs::remove_file(temp);
    }
    reg.staged = None;
    for dir in reg.created_dirs.drain(..).rev() {
        let _ = std::fs::remove_dir(dir);
    }
    std::mem::forget(reg);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporary_files_are_skipped_not_overwritten() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        // The names the next writes would take, left by a "killed" process
        // with this id.
        let next = SEQUENCE.load(Ordering::Relaxed);
        let stale: Vec<PathBuf> = (next..next + 3)
            .map(|n| {
                dir.path()
                    .join(format!(".out.txt.tmp.{}.{n}", std::process::id()))
            })
            .collect();
        for s in &stale {
            std::fs::write(s, b"stale").unwrap();
        }
        atomic_write(&path, |w| w.write_all(b"new\n")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new\n");
        for s in &stale {
            assert_eq!(std::fs::read(s).unwrap(), b"stale");
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    }
}

//! [`OutputBatch`]: a run's output files (and the directories made for
//! them) appear all together at the end, or not at all.

use std::path::{Path, PathBuf};

use super::atomic::registry;
use crate::error::{Error, Result};

#[cfg(doc)]
use super::atomic_write;

/// A run's outputs as one set: while the batch is open, [`atomic_write`]
/// (and so every writer of subdyn) leaves each file at its temporary name;
/// [`commit`](Self::commit) renames them all to their targets, in the order
/// they were written, and dropping the batch without committing removes
/// them and the directories [`create_output_dir`] made, so a run that fails
/// anywhere leaves none of its files. One batch is open at a time in a
/// process.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// use subdyn::io::{OutputBatch, atomic_write, create_output_dir};
/// let (a, b) = (dir.path().join("a.txt"), dir.path().join("new/b.txt"));
/// let batch = OutputBatch::begin()?;
/// atomic_write(&a, |w| w.write_all(b"a\n"))?;
/// create_output_dir(&dir.path().join("new"))?;
/// atomic_write(&b, |w| w.write_all(b"b\n"))?;
/// assert!(!a.exists() && !b.exists());
/// drop(batch); // a failed run: nothing is left
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
///
/// let batch = OutputBatch::begin()?;
/// create_output_dir(&dir.path().join("new"))?;
/// atomic_write(&a, |w| w.write_all(b"a\n"))?;
/// atomic_write(&b, |w| w.write_all(b"b\n"))?;
/// batch.commit()?;
/// assert!(a.exists() && b.exists());
/// # Ok::<(), subdyn::Error>(())
/// ```
#[derive(Debug)]
pub struct OutputBatch {
    committed: bool,
}

impl OutputBatch {
    /// Opens the batch; an error if one is already open.
    pub fn begin() -> Result<Self> {
        let mut reg = registry();
        if reg.staged.is_some() {
            return Err(Error::input("an output batch is already open"));
        }
        reg.staged = Some(Vec::new());
        reg.created_dirs.clear();
        Ok(OutputBatch { committed: false })
    }

    /// Renames every staged file to its target. On a failed rename the
    /// files not yet renamed are removed (those renamed stay: a rename
    /// cannot be undone).
    pub fn commit(mut self) -> Result<()> {
        self.committed = true;
        let mut reg = registry();
        let staged = reg.staged.take().unwrap_or_default();
        reg.created_dirs.clear();
        let mut failed = None;
        for (temp, path) in staged {
            if failed.is_none()
                && let Err(e) = std::fs::rename(&temp, &path)
            {
                failed = Some(Error::io(&path, e));
            }
            if failed.is_some() {
                let _ = std::fs::remove_file(&temp);
            }
            reg.live.retain(|t| *t != temp);
        }
        failed.map_or(Ok(()), Err)
    }
}

impl Drop for OutputBatch {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        let mut reg = registry();
        for (temp, _) in reg.staged.take().unwrap_or_default() {
            let _ = std::fs::remove_file(&temp);
            reg.live.retain(|t| *t != temp);
        }
        // Innermost first; a directory that is not empty stays.
        for dir in std::mem::take(&mut reg.created_dirs).into_iter().rev() {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Creates the directory `dir` and any missing parents for outputs; while
/// a batch is open, the ones it created are removed again if the run fails.
pub fn create_output_dir(dir: &Path) -> Result<()> {
    let missing: Vec<PathBuf> = dir
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .take_while(|a| !a.exists())
        .map(Path::to_path_buf)
        .collect();
    let mut reg = registry();
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    if reg.staged.is_some() {
        reg.created_dirs.extend(missing.into_iter().rev());
    }
    Ok(())
}

/// Fails unless `dir` can hold new output files: it is a directory that
/// takes a new file, or it does not exist and its nearest existing ancestor
/// is such a directory ([`create_output_dir`] will make it). Nothing is
/// left behind.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// use subdyn::io::check_output_dir_path;
/// assert!(check_output_dir_path(&dir.path().join("frames/a")).is_ok());
/// std::fs::write(dir.path().join("file"), b"x").unwrap();
/// assert!(check_output_dir_path(&dir.path().join("file")).is_err());
/// assert!(check_output_dir_path(&dir.path().join("file/sub")).is_err());
/// ```
pub fn check_output_dir_path(dir: &Path) -> Result<()> {
    let existing = dir
        .ancestors()
        .map(|a| {
            if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            }
        })
        .find(|a| a.exists())
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        return Err(Error::input(format!(
            "{}: {} is a file, not a directory for outputs",
            dir.display(),
            existing.display()
        )));
    }
    super::check_writable(&existing.join("probe"))
}

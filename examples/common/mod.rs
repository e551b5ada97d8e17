//! Shared by the examples (not an example itself): where they write.

use std::path::PathBuf;

/// `target/examples-out/` of this repository, created when missing: every
/// example writes its files there, never into the repository root or the
/// current directory.
pub fn output_dir() -> subdyn::Result<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/examples-out");
    std::fs::create_dir_all(&dir).map_err(|e| subdyn::Error::io(&dir, e))?;
    Ok(dir)
}

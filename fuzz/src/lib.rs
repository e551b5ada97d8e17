//! What every fuzz target shares: a memory budget the fuzzer's RSS limit
//! can check, and a private scratch directory for the readers that take a
//! path (the volume readers, tag files, OBJ tags).

use std::path::{Path, PathBuf};
use std::sync::Once;

/// The budget the targets run under (`--max-memory 512M`): libFuzzer runs
/// with `-rss_limit_mb=1024` (see `.ci/fuzz`), so an input that makes a
/// reader allocate past its own estimate by 2× is reported.
pub const BUDGET_BYTES: u64 = 512_000_000;

static INIT: Once = Once::new();

/// Sets the memory budget once per process.
pub fn init() {
    INIT.call_once(|| subdyn::memory::set_memory_budget(BUDGET_BYTES));
}

/// This process's scratch directory (created on first use), emptied of
/// `names` so that each input starts from nothing.
pub fn scratch(names: &[&str]) -> PathBuf {
    init();
    let dir = std::env::temp_dir().join(format!("subdyn-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    for name in names {
        let p = dir.join(name);
        if p.is_dir() {
            let _ = std::fs::remove_dir_all(&p);
        } else {
            let _ = std::fs::remove_file(&p);
        }
    }
    dir
}

/// Writes `bytes` to `dir/name` and returns the path.
pub fn file(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("scratch file");
    p
}

/// Parses `data` as a mesh and as a point cloud in `format`.
pub fn read_mesh_and_points(data: &[u8], format: subdyn::io::MeshFormat) {
    init();
    let name = Path::new("fuzz");
    let _ = subdyn::io::read_mesh_from_bytes(data, format, name);
    let _ = subdyn::io::read_points_from_bytes(data, format, name);
}

/// Writes `data` to the file `name` in the scratch directory and reads it
/// as a volume (the format from the name).
pub fn read_volume_file(name: &str, data: &[u8]) {
    let dir = scratch(&[name]);
    let _ = subdyn::io::read_volume(file(&dir, name, data), &Default::default());
}

/// `data` cut at each `separator` into at most `max` parts (the last part
/// keeps any further separators): how one fuzz input carries several files.
pub fn parts<'a>(data: &'a [u8], separator: &[u8], max: usize) -> Vec<&'a [u8]> {
    let mut out = Vec::new();
    let mut rest = data;
    while out.len() + 1 < max {
        match rest.windows(separator.len()).position(|w| w == separator) {
            Some(i) => {
                out.push(&rest[..i]);
                rest = &rest[i + separator.len()..];
            }
            None => break,
        }
    }
    out.push(rest);
    out
}

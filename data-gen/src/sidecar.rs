//! JSON sidecars: where they go, how paths inside them are written, and
//! writing them atomically with a stable layout.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;
use subdyn::math::Point3;

/// `generator` field of every sidecar.
pub const GENERATOR: &str = concat!("data-gen ", env!("CARGO_PKG_VERSION"));

/// `scan.ply` → `scan.json`, `scan.ply.gz` → `scan.json`.
pub fn sidecar_path(out: &Path) -> PathBuf {
    with_suffix(out, ".json")
}

/// `out` with its extensions (and a trailing `.gz`) replaced by `suffix`:
/// `with_suffix("a/scan.ply", ".truth.obj")` is `a/scan.truth.obj`.
pub fn with_suffix(out: &Path, suffix: &str) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let lower = name.to_ascii_lowercase();
    let trimmed = if lower.ends_with(".gz") {
        &name[..name.len() - 3]
    } else {
        &name[..]
    };
    let stem = match trimmed.rfind('.') {
        Some(i) if i > 0 => &trimmed[..i],
        _ => trimmed,
    };
    out.with_file_name(format!("{stem}{suffix}"))
}

/// How a sidecar names `target`: its file name when it sits in the sidecar's
/// directory (so a moved directory stays consistent), else the path as given.
pub fn path_from_sidecar(target: &Path, sidecar: &Path) -> String {
    let same_dir = target.parent().map(Path::to_path_buf).unwrap_or_default()
        == sidecar.parent().map(Path::to_path_buf).unwrap_or_default();
    match (same_dir, target.file_name()) {
        (true, Some(name)) => name.to_string_lossy().into_owned(),
        _ => target.to_string_lossy().into_owned(),
    }
}

/// Writes `value` as pretty JSON (plus a newline) to `path`, atomically.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising the sidecar")?;
    subdyn::io::atomic_write(path, |w| {
        w.write_all(text.as_bytes())?;
        w.write_all(b"\n")
    })?;
    Ok(())
}

/// Creates the directory `path` will be written in, if it is missing.
pub fn create_parent(path: &Path) -> Result<()> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the directory {}", dir.display())),
        _ => Ok(()),
    }
}

/// `[x, y, z]` for JSON.
pub fn xyz(p: &Point3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Bounding box and diagonal of a set of points, for JSON.
#[derive(Clone, Debug, Serialize)]
pub struct BoxJson {
    /// Smallest coordinates.
    pub min: [f64; 3],
    /// Largest coordinates.
    pub max: [f64; 3],
    /// Length of the diagonal.
    pub diagonal: f64,
}

/// The bounding box of `points` (zeros for none).
pub fn box_json(points: &[Point3]) -> BoxJson {
    let (lo, hi) =
        subdyn::math::bounding_box(points).unwrap_or((Point3::origin(), Point3::origin()));
    BoxJson {
        min: xyz(&lo),
        max: xyz(&hi),
        diagonal: (hi - lo).norm(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidecar_and_suffix_paths() {
        assert_eq!(
            sidecar_path(Path::new("a/scan.ply")),
            Path::new("a/scan.json")
        );
        assert_eq!(
            sidecar_path(Path::new("scan.ply.gz")),
            Path::new("scan.json")
        );
        assert_eq!(
            with_suffix(Path::new("a/s.ply"), ".truth.obj"),
            Path::new("a/s.truth.obj")
        );
        assert_eq!(sidecar_path(Path::new("noext")), Path::new("noext.json"));
        assert_eq!(
            path_from_sidecar(Path::new("d/m.obj"), Path::new("d/s.json")),
            "m.obj"
        );
        assert_eq!(
            path_from_sidecar(Path::new("e/m.obj"), Path::new("d/s.json")),
            "e/m.obj"
        );
    }
}

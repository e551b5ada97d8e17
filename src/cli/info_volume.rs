//! `subdyn info VOLUME [--json]`: grid, voxel-to-world map and value range of
//! a volume (NIfTI, slice directory, TIFF, EXR, raw + JSON).

use std::fmt::Write as _;
use std::path::Path;

use serde_json::json;

use subdyn::io::{MeshFormat, VolumeFormat, VolumeReadOptions, read_volume};

use super::common::{about_file, print_stdout, thousands};

/// Whether `path` names a volume rather than a mesh or point file.
pub fn is_volume(path: &Path) -> bool {
    MeshFormat::from_path(path).is_err() && VolumeFormat::from_path(path).is_ok()
}

/// Prints what `read_volume` finds in `path`.
pub fn run(path: &Path, as_json: bool) -> anyhow::Result<()> {
    let vf = read_volume(path, &VolumeReadOptions::default()).map_err(|e| about_file(e, path))?;
    let v = &vf.volume;
    let [nx, ny, nz] = v.dims();
    let (lo, hi) = v.range();
    let (blo, bhi) = v.world_bounds();
    let o = v.origin();
    let text = if as_json {
        let linear: Vec<[f64; 3]> = (0..3)
            .map(|r| [v.linear()[(r, 0)], v.linear()[(r, 1)], v.linear()[(r, 2)]])
            .collect();
        format!(
            "{}\n",
            json!({
                "file": path.display().to_string(),
                "kind": "volume",
                "format": vf.source,
                "dims": v.dims(),
                "spacing": v.spacing(),
                "origin": [o.x, o.y, o.z],
                "linear": linear,
                "world_box": {"min": [blo.x, blo.y, blo.z], "max": [bhi.x, bhi.y, bhi.z]},
                "range": [lo, hi],
                "iso_value": vf.iso_value,
                "notes": vf.notes,
            })
        )
    } else {
        let mut s = String::new();
        let _ = writeln!(s, "file:                 {}", path.display());
        let _ = writeln!(s, "format:               {}", vf.source);
        let _ = writeln!(
            s,
            "dims:                 {nx} × {ny} × {nz} ({} voxels)",
            thousands(nx * ny * nz)
        );
        let [sx, sy, sz] = v.spacing();
        let _ = writeln!(s, "spacing:              {sx} × {sy} × {sz}");
        let _ = writeln!(s, "origin:               ({}, {}, {})", o.x, o.y, o.z);
        let _ = writeln!(
            s,
            "world box:            ({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3})",
            blo.x, blo.y, blo.z, bhi.x, bhi.y, bhi.z
        );
        let _ = writeln!(s, "range:                {lo} to {hi}");
        if let Some(iso) = vf.iso_value {
            let _ = writeln!(s, "iso value (sidecar):  {iso}");
        }
        for n in &vf.notes {
            let _ = writeln!(s, "note:                 {n}");
        }
        s
    };
    print_stdout(&text)
}

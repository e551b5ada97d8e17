//! JSON sidecars: data-gen's `volume.json` / `BASE.json`, which is also the
//! header of a raw volume.
//!
//! Fields read (all others ignored): `dims` `[nx, ny, nz]` (required: a JSON
//! file without it, such as a BIDS sidecar, is not a volume sidecar),
//! `spacing`, `origin` (mm; world = origin + index × spacing), `dtype`
//! (`u8` … `f64`, default `f32`), `byte_order` (`little` or `big`, default
//! little), `header_bytes` (bytes before the voxels, default 0), `files` (the
//! data file of a raw volume), `intensity_scale` `{slope, intercept}`
//! (physical = slope × stored + intercept) and `iso_value` (stored units).

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::{Error, Result};

/// A parsed sidecar.
#[derive(Clone, Debug)]
pub(crate) struct Sidecar {
    /// The JSON file.
    pub path: PathBuf,
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Voxel size, mm.
    pub spacing: Option<[f64; 3]>,
    /// World position of voxel (0, 0, 0).
    pub origin: Option<[f64; 3]>,
    /// Stored sample type name.
    pub dtype: Option<String>,
    /// `little` or `big`.
    pub byte_order: Option<String>,
    /// Bytes before the voxels of a raw file.
    pub header_bytes: u64,
    /// Data files, relative to the sidecar's directory.
    pub files: Vec<String>,
    /// `(slope, intercept)`: physical = slope × stored + intercept.
    pub scale: Option<(f64, f64)>,
    /// The true surface's level, stored units.
    pub iso_value: Option<f64>,
}

/// Where the sidecar of `volume` would be: `DIR/volume.json` for a slice
/// directory, `BASE.json` for `BASE.nii.gz`, `BASE.nii`, `BASE.tif(f)`,
/// `BASE.raw`, `BASE.exr`, and the file itself for a `.json`.
pub(crate) fn sidecar_path(volume: &Path) -> PathBuf {
    if volume.is_dir() {
        return volume.join("volume.json");
    }
    let name = volume
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".json") {
        return volume.to_path_buf();
    }
    let base = [".nii.gz", ".nii", ".tiff", ".tif", ".raw", ".exr"]
        .iter()
        .find(|e| lower.ends_with(*e))
        .map_or(name.as_str(), |e| &name[..name.len() - e.len()]);
    volume.with_file_name(format!("{base}.json"))
}

/// The sidecar at `path`: `None` when there is no such file or it is JSON
/// without `dims`; an error naming the file when it is not JSON or a field
/// is malformed.
pub(crate) fn read_sidecar(path: &Path) -> Result<Option<Sidecar>> {
    if !path.is_file() {
        return Ok(None);
    }
    let bytes = crate::io::read_input(path)?;
    let json: Value = serde_json::from_slice(&bytes)
        .map_err(|e| Error::parse(path, e.line(), format!("not valid JSON: {e}")))?;
    if json.get("dims").is_none() {
        return Ok(None);
    }
    let bad = |field: &str, what: &str| {
        Error::parse(
            path,
            0,
            format!("'{field}' must be {what}, found {}", json[field]),
        )
    };
    let triple = |field: &str| -> Result<Option<[f64; 3]>> {
        match json.get(field) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(a)) if a.len() == 3 => {
                let v: Vec<f64> = a.iter().filter_map(Value::as_f64).collect();
                if v.len() == 3 && v.iter().all(|x| x.is_finite()) {
                    Ok(Some([v[0], v[1], v[2]]))
                } else {
                    Err(bad(field, "three finite numbers"))
                }
            }
            Some(_) => Err(bad(field, "three finite numbers")),
        }
    };
    let dims = match json["dims"].as_array().map(|a| {
        a.iter()
            .map(|v| v.as_u64().filter(|&n| n >= 1))
            .collect::<Option<Vec<u64>>>()
    }) {
        Some(Some(d)) if d.len() == 3 => [d[0], d[1], d[2]].map(|n| n as usize),
        _ => return Err(bad("dims", "three whole numbers ≥ 1")),
    };
    let spacing = triple("spacing")?;
    if spacing.is_some_and(|s| s.iter().any(|&x| x <= 0.0)) {
        return Err(bad("spacing", "three positive numbers"));
    }
    let text = |field: &str| json.get(field).and_then(Value::as_str).map(str::to_string);
    let header_bytes = match json.get("header_bytes") {
        None | Some(Value::Null) => 0,
        Some(v) => v
            .as_u64()
            .ok_or_else(|| bad("header_bytes", "a whole number ≥ 0"))?,
    };
    let files = match json.get("files") {
        Some(Value::Array(a)) => a
            .iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect(),
        _ => Vec::new(),
    };
    let scale = match json.get("intensity_scale") {
        None | Some(Value::Null) => None,
        Some(s) => {
            let slope = s["slope"].as_f64().filter(|x| x.is_finite() && *x != 0.0);
            let intercept = s["intercept"].as_f64().filter(|x| x.is_finite());
            match (slope, intercept) {
                (Some(a), Some(b)) => Some((a, b)),
                _ => {
                    return Err(bad(
                        "intensity_scale",
                        "{\"slope\": non-zero, \"intercept\": finite}",
                    ));
                }
            }
        }
    };
    let iso_value = match json.get("iso_value") {
        None | Some(Value::Null) => None,
        Some(v) => Some(
            v.as_f64()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad("iso_value", "a finite number"))?,
        ),
    };
    Ok(Some(Sidecar {
        path: path.to_path_buf(),
        dims,
        spacing,
        origin: triple("origin")?,
        dtype: text("dtype"),
        byte_order: text("byte_order"),
        header_bytes,
        files,
        scale,
        iso_value,
    }))
}

//! Writing one run: the volume in its format, the ground-truth mesh and the
//! JSON sidecar, all or nothing.
//!
//! Single files go through [`subdyn::io::atomic_write`]. Stacks are written
//! into a hidden staging directory beside `OUT` (`.OUT.tmp.<pid>`), complete
//! with `volume.json` and `truth.obj`, and renamed to `OUT` at the end; an
//! existing `OUT` is replaced only when it holds nothing but a previous stack.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::Serialize;
use serde_json::Value;

use crate::measure::enclosed_volume;
use crate::sidecar::GENERATOR;
use crate::truth::GroundTruth;
use crate::volume::VolumeArgs;
use crate::volume::bias::BiasField;
use crate::volume::format::{OutputPaths, VolumeFormat};
use crate::volume::grid::Grid;
use crate::volume::nifti::{NIFTI_VOX_OFFSET, write_f32_le, write_nifti};
use crate::volume::noise::NoiseModel;
use crate::volume::rasterise::RasterReport;
use crate::volume::slices::{
    IntensityScale, Written, tiff_bytes, write_exr_stack, write_png_stack,
};

/// What the pipeline measured, for the sidecar.
pub struct Facts<'a> {
    /// The format written.
    pub format: VolumeFormat,
    /// The lattice.
    pub grid: Grid,
    /// The rasterised surface.
    pub truth: &'a GroundTruth,
    /// Rasterisation counts.
    pub raster: RasterReport,
    /// `Σ f × voxel volume` before blur.
    pub fraction_volume: f64,
    /// The bias field, when one was applied.
    pub bias: Option<BiasField>,
}

/// The JSON sidecar (`OUT/volume.json` or `BASE.json`). For `raw` it is also
/// the header: `dims`, `spacing`, `origin`, `dtype`, `byte_order`, `header_bytes`.
#[derive(Serialize)]
struct Sidecar<'a> {
    generator: &'static str,
    format: VolumeFormat,
    /// Data files relative to this file's directory (slices in z order).
    files: Vec<String>,
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    index_to_world: &'static str,
    units: &'static str,
    layout: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    slice_convention: Option<&'static str>,
    dtype: &'static str,
    byte_order: &'static str,
    /// Bytes before the first voxel of a data file (352 for NIfTI, 0 for raw).
    header_bytes: usize,
    /// `physical = slope × stored + intercept`.
    intensity_scale: IntensityScale,
    /// Iso-value of the true surface in stored units (unrounded).
    iso_value: f64,
    /// The same in physical intensity units: `(inside + outside) / 2`.
    iso_value_physical: f64,
    iso_note: &'static str,
    /// Range of the stored data, physical units.
    data_range: [f32; 2],
    /// Ground-truth mesh, relative to this file's directory.
    truth_mesh: String,
    truth_mesh_volume: f64,
    /// `Σ f × sx sy sz`: the volume inside the surface as rasterised.
    fraction_volume: f64,
    /// Shape name, or `file`.
    shape: &'a str,
    /// Source, topology, box, area, volume (and analytic facts) of the truth.
    truth: &'a Value,
    parameters: Parameters,
    rasterisation: &'a RasterReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    bias_field: Option<&'a BiasField>,
}

#[derive(Serialize)]
struct Parameters {
    inside: f64,
    outside: f64,
    blur_sigma_mm: f64,
    noise_std: f64,
    noise_model: NoiseModel,
    inhomogeneity: f64,
    seed: u64,
    margin: f64,
    supersample: usize,
    dims_requested: Option<[usize; 3]>,
    spacing_requested: Option<[f64; 3]>,
    origin_requested: Option<[f64; 3]>,
    shape_resolution: Option<usize>,
}

/// Writes the volume, `truth`, and the sidecar for `data` (physical f32 intensities).
pub fn write_outputs(
    paths: &OutputPaths,
    data: &[f32],
    args: &VolumeArgs,
    facts: &Facts,
) -> Result<()> {
    let levels = [args.inside, args.outside];
    if facts.format.is_stack() {
        let stage = staging_dir(&paths.volume)?;
        let result = (|| -> Result<()> {
            let written = match facts.format {
                VolumeFormat::Exr => write_exr_stack(&stage, &facts.grid, data)?,
                VolumeFormat::Png8 => write_png_stack(&stage, &facts.grid, data, &levels, 8)?,
                _ => write_png_stack(&stage, &facts.grid, data, &levels, 16)?,
            };
            let truth = stage.join(file_name(&paths.truth)?);
            subdyn::io::write_mesh(&truth, &facts.truth.mesh, None)?;
            let json = sidecar_json(paths, data, args, facts, written)?;
            let sidecar = stage.join(file_name(&paths.sidecar)?);
            subdyn::io::atomic_write(&sidecar, |w| w.write_all(&json))?;
            replace_dir(&stage, &paths.volume)
        })();
        if result.is_err() {
            let _ = std::fs::remove_dir_all(&stage);
        }
        return result;
    }
    let written = match facts.format {
        VolumeFormat::Tiff | VolumeFormat::TiffF32 => {
            let (bytes, written) = tiff_bytes(
                &facts.grid,
                data,
                &levels,
                facts.format == VolumeFormat::TiffF32,
            )?;
            subdyn::io::atomic_write(&paths.volume, |w| w.write_all(&bytes))?;
            written
        }
        VolumeFormat::Raw => {
            subdyn::io::atomic_write(&paths.volume, |w| write_f32_le(w, data))?;
            Written {
                files: Vec::new(),
                dtype: "f32",
                scale: IntensityScale::IDENTITY,
            }
        }
        _ => {
            let gzip = facts.format == VolumeFormat::NiftiGz;
            subdyn::io::atomic_write(&paths.volume, |w| write_nifti(w, &facts.grid, data, gzip))?;
            Written {
                files: Vec::new(),
                dtype: "f32",
                scale: IntensityScale::IDENTITY,
            }
        }
    };
    let written = Written {
        files: vec![file_name(&paths.volume)?],
        ..written
    };
    subdyn::io::write_mesh(&paths.truth, &facts.truth.mesh, None)?;
    let json = sidecar_json(paths, data, args, facts, written)?;
    subdyn::io::atomic_write(&paths.sidecar, |w| w.write_all(&json))?;
    Ok(())
}

/// The sidecar's bytes (pretty JSON, newline-terminated).
fn sidecar_json(
    paths: &OutputPaths,
    data: &[f32],
    args: &VolumeArgs,
    facts: &Facts,
    written: Written,
) -> Result<Vec<u8>> {
    let grid = &facts.grid;
    let iso_physical = 0.5 * (args.inside + args.outside);
    let (lo, hi) = data
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let nifti = matches!(facts.format, VolumeFormat::Nifti | VolumeFormat::NiftiGz);
    let sidecar = Sidecar {
        generator: GENERATOR,
        format: facts.format,
        files: written.files,
        dims: grid.dims,
        spacing: grid.spacing,
        origin: grid.origin,
        index_to_world: "world = origin + index * spacing (voxel centres; voxel i covers origin + (i -/+ 0.5) * spacing)",
        units: "mm",
        layout: "x fastest, then y, then z",
        slice_convention: match facts.format {
            VolumeFormat::Raw | VolumeFormat::Nifti | VolumeFormat::NiftiGz => None,
            _ => Some(
                "column = x, row = y (row 0, the first row in the file, is y index 0), slice order = z; \
                 stack files slice_<z>.<ext> numbered without zero padding: sort by number",
            ),
        },
        dtype: written.dtype,
        byte_order: match facts.format {
            VolumeFormat::Raw | VolumeFormat::Nifti | VolumeFormat::NiftiGz => "little",
            _ => "as defined by the image format",
        },
        header_bytes: if nifti { NIFTI_VOX_OFFSET } else { 0 },
        intensity_scale: written.scale,
        iso_value: written.scale.stored(iso_physical),
        iso_value_physical: iso_physical,
        iso_note: "the true surface is the 0.5 level of the partial-volume fraction before blur; \
                   where a bias field is applied the local iso-value is b(x) times this; \
                   Rician noise raises the mean of dark regions",
        data_range: [lo, hi],
        truth_mesh: file_name(&paths.truth)?,
        truth_mesh_volume: enclosed_volume(&facts.truth.mesh).abs(),
        fraction_volume: facts.fraction_volume,
        shape: &facts.truth.name,
        truth: &facts.truth.info,
        parameters: Parameters {
            inside: args.inside,
            outside: args.outside,
            blur_sigma_mm: args.blur,
            noise_std: args.noise,
            noise_model: args.noise_model,
            inhomogeneity: args.inhomogeneity,
            seed: args.seed,
            margin: args.margin,
            supersample: args.supersample,
            dims_requested: args.dims,
            spacing_requested: args.spacing,
            origin_requested: args.origin,
            shape_resolution: args.shape_resolution,
        },
        rasterisation: &facts.raster,
        bias_field: facts.bias.as_ref(),
    };
    let mut json = serde_json::to_vec_pretty(&sidecar)?;
    json.push(b'\n');
    Ok(json)
}

/// The last component of `path` as a string.
fn file_name(path: &Path) -> Result<String> {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .with_context(|| format!("{}: not a file name", path.display()))
}

/// Creates an empty hidden directory beside `out` to build a stack in.
fn staging_dir(out: &Path) -> Result<PathBuf> {
    let name = file_name(out)?;
    let stage = out.with_file_name(format!(".{name}.tmp.{}", std::process::id()));
    if stage.exists() {
        std::fs::remove_dir_all(&stage)
            .with_context(|| format!("{}: cannot clear", stage.display()))?;
    }
    std::fs::create_dir(&stage)
        .with_context(|| format!("{}: cannot create the output directory", stage.display()))?;
    Ok(stage)
}

/// Fails early when a stack would have to replace a directory that is not a
/// previous stack (checked again when renaming).
pub fn check_target(paths: &OutputPaths, format: VolumeFormat) -> Result<()> {
    let out = &paths.volume;
    if format.is_stack() && out.exists() && !is_previous_stack(out) {
        bail!(
            "{}: exists and is not a data-gen volume stack; remove it or choose another -o",
            out.display()
        );
    }
    if !format.is_stack() && out.is_dir() {
        bail!(
            "{}: is a directory; give a file name for {}",
            out.display(),
            crate::volume::format_name(format)
        );
    }
    Ok(())
}

/// Renames `stage` to `out`, first removing an `out` that is a previous stack
/// (only `slice_<n>.png|exr`, `volume.json`, `truth.obj` inside).
fn replace_dir(stage: &Path, out: &Path) -> Result<()> {
    if out.exists() {
        if !is_previous_stack(out) {
            bail!(
                "{}: exists and is not a data-gen volume stack; remove it or choose another -o",
                out.display()
            );
        }
        std::fs::remove_dir_all(out)
            .with_context(|| format!("{}: cannot replace", out.display()))?;
    }
    std::fs::rename(stage, out).with_context(|| format!("{}: cannot create", out.display()))
}

fn is_previous_stack(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries.into_iter().all(|e| {
        let Ok(e) = e else { return false };
        let name = e.file_name().to_string_lossy().into_owned();
        let is_slice = name
            .strip_prefix("slice_")
            .and_then(|r| r.strip_suffix(".png").or_else(|| r.strip_suffix(".exr")))
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
        e.file_type().is_ok_and(|t| t.is_file())
            && (is_slice || name == "volume.json" || name == "truth.obj")
    })
}

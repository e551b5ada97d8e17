//! [`read_volume`]: any supported volume file or directory to a [`Volume`]
//! in world coordinates and physical intensities.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::decoded::{Decoded, Placement};
use super::detect::VolumeFormat;
use super::exr::read_exr_file;
use super::nifti::read_nifti;
use super::raw::read_raw;
use super::sidecar::{Sidecar, read_sidecar, sidecar_path};
use super::slices::read_slice_dir;
use super::tiff::read_tiff_stack;
use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::volume::Volume;

/// Command-line overrides of the voxel-to-world map
/// (`--spacing sx,sy,sz`, `--origin ox,oy,oz`; world = origin + index × spacing).
///
/// When given they always win (the user asked for them), with a note saying
/// what they replaced: `spacing` makes the map axis-aligned with that
/// spacing (a NIfTI rotation is dropped), `origin` moves voxel (0, 0, 0).
/// Both default to `None`: take the map from the file.
#[derive(Clone, Debug, Default)]
pub struct VolumeReadOptions {
    /// Voxel size along x, y, z in world units (mm), all > 0.
    pub spacing: Option<[Real; 3]>,
    /// World position of the centre of voxel (0, 0, 0).
    pub origin: Option<[Real; 3]>,
}

/// A volume read from a file, with what the reader decided.
#[derive(Clone, Debug)]
pub struct VolumeFile {
    /// Samples (f32, physical units where the file says how) and the
    /// voxel-to-world map.
    pub volume: Volume,
    /// Format description, e.g. `NIfTI-1 (gzip), u8, little-endian`.
    pub source: String,
    /// The true surface's level from a data-gen sidecar, in the units of
    /// `volume`'s samples (the sidecar's `intensity_scale` applied, as to the data).
    pub iso_value: Option<f64>,
    /// Decisions worth telling the user: where spacing and origin came from,
    /// scalings applied, colour converted, …
    pub notes: Vec<String>,
}

/// Reads the volume at `path` (format from [`VolumeFormat::from_path`]).
///
/// Samples: voxels x fastest; slice images have column = x, row = y (the
/// first row of the file is y = 0) and file or page order = z (slice files
/// sorted by the number in their name). Values are f32: NIfTI's
/// `scl_slope`/`scl_inter` are applied; for other formats a data-gen sidecar's
/// `intensity_scale` is applied (physical = slope × stored + intercept), else
/// the stored values are returned unchanged. `iso_value` is given in the same
/// units as the returned samples.
///
/// Voxel-to-world map, first source that has it:
/// 1. `options` (`--spacing`, `--origin`), always;
/// 2. NIfTI: the sform if `sform_code > 0`, else the qform if
///    `qform_code > 0`, else `pixdim` scaling — NIfTI world coordinates,
///    RAS+ millimetres (x to the subject's right, y anterior, z superior;
///    DICOM/ITK's LPS has x and y negated);
/// 3. a data-gen sidecar (`DIR/volume.json` for a directory, `BASE.json`
///    beside a file): `spacing`, `origin`;
/// 4. TIFF: the ImageJ description (`unit=`, `spacing=`) with the
///    X/YResolution tags (other TIFF resolutions are typically 72 dpi and
///    are ignored);
/// 5. spacing 1, origin 0, with a note asking for `--spacing`.
///
/// Errors (one [`Error`] naming the file): unreadable or malformed files,
/// sidecar dimensions that disagree with the data, NaN or infinite samples,
/// a singular map, bad options.
pub fn read_volume(path: impl AsRef<Path>, options: &VolumeReadOptions) -> Result<VolumeFile> {
    let path = path.as_ref();
    check_options(options)?;
    if !path.exists() {
        return Err(Error::io(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such file or directory"),
        ));
    }
    let format = VolumeFormat::from_path(path)?;
    let sidecar = read_sidecar(&sidecar_path(path))?;
    let decoded = match format {
        VolumeFormat::Nifti => read_nifti(path)?,
        VolumeFormat::Raw => read_raw(path, sidecar.as_ref())?,
        VolumeFormat::SliceDirectory => read_slice_dir(path)?,
        VolumeFormat::Tiff => read_tiff_stack(path)?,
        VolumeFormat::Exr => read_exr_file(path)?,
    };
    finish(path, decoded, sidecar.as_ref(), options)
}

/// Checks the sidecar against the data, applies its intensity scale and
/// settles the voxel-to-world map.
fn finish(
    path: &Path,
    mut decoded: Decoded,
    sidecar: Option<&Sidecar>,
    options: &VolumeReadOptions,
) -> Result<VolumeFile> {
    let mut notes = std::mem::take(&mut decoded.notes);
    let mut iso_value = None;
    if let Some(side) = sidecar {
        if side.dims != decoded.dims {
            return Err(Error::parse(
                &side.path,
                0,
                format!(
                    "the sidecar says dims {:?} but {} holds {:?}",
                    side.dims,
                    path.display(),
                    decoded.dims
                ),
            ));
        }
        let (slope, intercept) = side.scale.unwrap_or((1.0, 0.0));
        if !decoded.physical && (slope, intercept) != (1.0, 0.0) {
            for v in decoded.data.iter_mut() {
                *v = (slope * f64::from(*v) + intercept) as f32;
            }
            notes.push(format!(
                "intensity_scale from {} applied: value = {slope} × stored {intercept:+}",
                file_name(&side.path)
            ));
        }
        iso_value = side.iso_value.map(|iso| slope * iso + intercept);
    }
    let (linear, origin) = world_map(&decoded.placement, sidecar, options, &mut notes);
    let volume =
        Volume::with_affine(decoded.dims, decoded.data, linear, origin).map_err(|e| match e {
            Error::Input(m) => Error::parse(path, 0, m),
            other => other,
        })?;
    Ok(VolumeFile {
        volume,
        source: decoded.source,
        iso_value,
        notes,
    })
}

/// The voxel-to-world map by the precedence of [`read_volume`].
fn world_map(
    placement: &Placement,
    sidecar: Option<&Sidecar>,
    options: &VolumeReadOptions,
    notes: &mut Vec<String>,
) -> (Matrix3<Real>, Point3) {
    let diagonal = |s: [Real; 3]| Matrix3::from_diagonal(&Vector3::from(s));
    match placement {
        Placement::Affine { linear, origin } => {
            let linear = match options.spacing {
                Some(s) => {
                    notes.push(format!(
                        "spacing {s:?} from --spacing replaces the file's map (axis-aligned)"
                    ));
                    diagonal(s)
                }
                None => *linear,
            };
            let origin = match options.origin {
                Some(o) => {
                    notes.push(format!("origin {o:?} from --origin"));
                    Point3::from(o)
                }
                None => *origin,
            };
            (linear, origin)
        }
        Placement::Grid { spacing } => {
            let side_name = sidecar.map(|s| file_name(&s.path)).unwrap_or_default();
            let spacing = if let Some(s) = options.spacing {
                notes.push(format!("spacing {s:?} from --spacing"));
                s
            } else if let Some(s) = sidecar.and_then(|s| s.spacing) {
                notes.push(format!("spacing {s:?} from {side_name}"));
                s
            } else if let Some(s) = spacing {
                notes.push(format!("spacing {s:?} from the ImageJ metadata"));
                *s
            } else {
                notes.push("no spacing in the file: 1 assumed (give --spacing)".into());
                [1.0; 3]
            };
            let origin = if let Some(o) = options.origin {
                notes.push(format!("origin {o:?} from --origin"));
                o
            } else if let Some(o) = sidecar.and_then(|s| s.origin) {
                notes.push(format!("origin {o:?} from {side_name}"));
                o
            } else {
                notes.push("no origin in the file: 0 assumed (give --origin)".into());
                [0.0; 3]
            };
            (diagonal(spacing), Point3::from(origin))
        }
    }
}

/// `--spacing` must be positive and finite, `--origin` finite.
fn check_options(options: &VolumeReadOptions) -> Result<()> {
    if let Some(s) = options.spacing
        && !s.iter().all(|x| x.is_finite() && *x > 0.0)
    {
        return Err(Error::input(format!(
            "--spacing {s:?}: every voxel size must be a positive number"
        )));
    }
    if let Some(o) = options.origin
        && !o.iter().all(|x| x.is_finite())
    {
        return Err(Error::input(format!(
            "--origin {o:?}: coordinates must be finite numbers"
        )));
    }
    Ok(())
}

/// The last component of `path`, for notes.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

//! `data-gen volume`: a closed shape rasterised to an intensity volume with
//! exact ground truth, as MRI or CT would see it.
//!
//! Pipeline (one file per step):
//! 1. the surface: a built-in shape or `--mesh FILE`, checked closed ([`mesh`]);
//! 2. the grid: `world = origin + index × spacing`, fitted around the shape
//!    unless given ([`grid`]);
//! 3. the partial-volume fraction `f ∈ [0, 1]` of every voxel, exact along z,
//!    n × n supersampled in x, y ([`rasterise`]);
//! 4. `f ← G_σ * f`, σ in mm on every axis ([`blur`]);
//! 5. `I = outside + (inside − outside) f`;
//! 6. `I ← b(x) I`, a smooth quadratic bias field in `[1 − A, 1 + A]` ([`bias`]);
//! 7. Gaussian or Rician noise of standard deviation `--noise` ([`noise`]);
//! 8. the volume, the ground-truth mesh and a JSON sidecar ([`slices`],
//!    [`nifti`], [`format`] for file names).
//!
//! The true surface is the 0.5 level of `f`, so its iso-value is
//! `(inside + outside) / 2` in physical units (before bias and noise, which
//! the sidecar records). Output is byte-identical for the same arguments and
//! seed, whatever the number of threads.
//!
//! ## Outputs and conventions
//!
//! | `--format` | volume | stored | sidecar, truth |
//! |---|---|---|---|
//! | `png8`, `png16` | directory `OUT/` of `slice_0.png … slice_<nz−1>.png` | grey u8 / u16, linearly scaled to the full range | `OUT/volume.json`, `OUT/truth.obj` |
//! | `exr` | directory `OUT/` of `slice_<z>.exr`, one layer, one f32 channel `Y`, ZIP | f32 | same |
//! | `tiff`, `tiff-f32` | one multi-page TIFF `BASE.tif`, a page per z, X/YResolution = 1/spacing, ImageJ description | u16 (scaled) / f32 | `BASE.json`, `BASE.truth.obj` |
//! | `raw` | `BASE.raw`, little-endian f32, no header | f32 | `BASE.json` is the header |
//! | `nifti`, `nifti-gz` | NIfTI-1 `BASE.nii` / `BASE.nii.gz`, FLOAT32, `vox_offset` 352, qform = sform = 1 | f32 | `BASE.json`, `BASE.truth.obj` |
//!
//! - Voxels x fastest, then y, then z. Slice images: column = x, row = y (row 0,
//!   the first row of the file, is y index 0), file or page order = z. Stack
//!   files are numbered without zero padding (`slice_9.png`, `slice_10.png`),
//!   so readers must sort them by number.
//! - Scaled formats store `round((I − intercept) / slope)`; the sidecar's
//!   `intensity_scale` gives `I = slope × stored + intercept` (the lowest of the
//!   data, inside and outside maps to 0, the highest to 255 or 65535), and
//!   `iso_value` is the true surface's level in stored units.
//! - The sidecar also holds `dims`, `spacing`, `origin`, `dtype`, `byte_order`,
//!   `header_bytes`, the truth mesh path (relative), its facts, the measured
//!   `fraction_volume` and every parameter.
//! - Noise: `gaussian` adds σ n (CT-like); `rician` returns
//!   `√((I + σ n₁)² + (σ n₂)²)` (MRI magnitude).

#[path = "volume_bias.rs"]
pub mod bias;
#[path = "volume_blur.rs"]
pub mod blur;
#[path = "volume_format.rs"]
pub mod format;
#[path = "volume_grid.rs"]
pub mod grid;
#[path = "volume_mesh.rs"]
pub mod mesh;
#[path = "volume_nifti.rs"]
pub mod nifti;
#[path = "volume_noise.rs"]
pub mod noise;
#[path = "volume_output.rs"]
pub mod output;
#[path = "volume_parallel.rs"]
pub mod parallel;
#[path = "volume_rasterise.rs"]
pub mod rasterise;
#[path = "volume_slices.rs"]
pub mod slices;

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;

use crate::shapes::ShapeKind;
use crate::truth::{ShapeOptions, TruthSource, ground_truth, parse_triple};
use format::VolumeFormat;
use grid::{GridRequest, fitted_grid};
use noise::NoiseModel;

/// Options of `data-gen volume`.
#[derive(Args, Debug, Clone)]
pub struct VolumeArgs {
    /// Built-in shape to rasterise (or give --mesh FILE).
    #[arg(value_enum, required_unless_present = "mesh", conflicts_with = "mesh")]
    pub shape: Option<ShapeKind>,

    /// Any closed mesh (OBJ, PLY, OFF) to rasterise instead of a built-in shape.
    #[arg(long, value_name = "FILE")]
    pub mesh: Option<PathBuf>,

    /// Output: a directory for png8 / png16 / exr stacks, a file otherwise
    /// (.tif, .raw, .nii, .nii.gz; the extension is appended when missing).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: PathBuf,

    /// Volume format [default: from OUT's extension, else png16].
    #[arg(long, value_enum)]
    pub format: Option<VolumeFormat>,

    /// Voxels along x, y, z [default: 64 along the longest axis, isotropic].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_dims)]
    pub dims: Option<[usize; 3]>,

    /// Voxel size along x, y, z in mm; may differ per axis [default: fitted, isotropic].
    #[arg(long, value_name = "SX,SY,SZ", value_parser = parse_triple, allow_hyphen_values = true)]
    pub spacing: Option<[f64; 3]>,

    /// World position of the centre of voxel (0,0,0) [default: grid centred on the shape].
    #[arg(long, value_name = "OX,OY,OZ", value_parser = parse_triple, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,

    /// Empty space around the shape's bounding box, on every side, as a fraction of its largest extent.
    #[arg(
        long,
        value_name = "F",
        default_value_t = 0.15,
        allow_hyphen_values = true
    )]
    pub margin: f64,

    /// Intensity inside the shape.
    #[arg(
        long,
        value_name = "I",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub inside: f64,

    /// Intensity outside the shape.
    #[arg(
        long,
        value_name = "O",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub outside: f64,

    /// Standard deviation of the Gaussian blur in mm (same on every axis, so
    /// σ/spacing voxels); 0 for none.
    #[arg(
        long,
        value_name = "SIGMA_MM",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub blur: f64,

    /// Noise standard deviation, in intensity units; 0 for none.
    #[arg(
        long,
        value_name = "STD",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub noise: f64,

    /// Noise model: gaussian (CT-like, additive) or rician (MRI magnitude).
    #[arg(long, value_enum, default_value_t = NoiseModel::Gaussian)]
    pub noise_model: NoiseModel,

    /// Amplitude A of the multiplicative bias field (0 ≤ A < 1): intensities
    /// are scaled by a smooth quadratic field between 1 − A and 1 + A.
    #[arg(
        long,
        value_name = "A",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub inhomogeneity: f64,

    /// Seed of the noise and the bias field.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,

    /// Sample lines per voxel along x and along y for the partial volume (1..=16).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub supersample: usize,

    /// Resolution of a built-in shape (see `data-gen shape --help`) [default: per shape].
    #[arg(long, value_name = "R")]
    pub shape_resolution: Option<usize>,

    #[command(flatten)]
    pub shape_options: ShapeOptions,
}

/// Runs `data-gen volume`: rasterises, filters and writes the volume, the
/// ground-truth mesh and the sidecar.
pub fn run(args: &VolumeArgs) -> Result<()> {
    check_scalars(args)?;
    let (format, paths) = format::output_paths(&args.output, args.format)?;
    output::check_target(&paths, format)?;
    let truth_source = match (args.shape, &args.mesh) {
        (Some(kind), None) => {
            TruthSource::Shape(kind, args.shape_options.params(args.shape_resolution))
        }
        (None, Some(file)) => TruthSource::File(file.clone()),
        _ => bail!(
            "give either a SHAPE (sphere, ellipsoid, torus, genus2, bulb, anvil) or --mesh FILE"
        ),
    };
    let source = ground_truth(&truth_source)?;
    mesh::check_closed(&source.mesh, &source_name(&truth_source))?;
    let (lo, hi) = mesh::mesh_bounds(&source.mesh)?;
    let grid = fitted_grid(
        lo,
        hi,
        &GridRequest {
            dims: args.dims,
            spacing: args.spacing,
            origin: args.origin,
            margin: args.margin,
        },
    )?;

    let surface = mesh::MeshCrossings::new(&source.mesh)?;
    let (mut data, raster) = rasterise::inside_fractions(&grid, &surface, args.supersample);
    let fraction_volume = data.iter().map(|&f| f64::from(f)).sum::<f64>() * grid.voxel_volume();
    check_overlap(fraction_volume, (lo, hi), &grid)?;
    blur::gaussian_blur(&mut data, &grid, args.blur);
    let (inside, outside) = (args.inside, args.outside);
    for v in data.iter_mut() {
        *v = (outside + (inside - outside) * f64::from(*v)) as f32;
    }
    let bias = bias::apply_bias_field(&mut data, &grid, args.inhomogeneity, args.seed);
    noise::add_noise(&mut data, args.noise, args.noise_model, args.seed);

    let facts = output::Facts {
        format,
        grid,
        truth: &source,
        raster,
        fraction_volume,
        bias,
    };
    output::write_outputs(&paths, &data, args, &facts)?;
    eprintln!(
        "data-gen volume: wrote {} ({} {}x{}x{}, spacing {:?} mm) and {}",
        paths.volume.display(),
        format_name(format),
        grid.dims[0],
        grid.dims[1],
        grid.dims[2],
        grid.spacing,
        paths.sidecar.display()
    );
    Ok(())
}

/// Errors when the shape misses the grid; warns (one line on stderr) when the
/// shape's bounding box sticks out of the grid, so that part of it is cut off.
fn check_overlap(
    fraction_volume: f64,
    (lo, hi): ([f64; 3], [f64; 3]),
    grid: &grid::Grid,
) -> Result<()> {
    if fraction_volume <= 0.0 {
        bail!(
            "the shape lies outside the grid (dims {:?}, spacing {:?}, origin {:?}); the volume would be constant",
            grid.dims,
            grid.spacing,
            grid.origin
        );
    }
    let outside = (0..3).any(|k| {
        let first = grid.origin[k] - 0.5 * grid.spacing[k];
        let last = grid.origin[k] + (grid.dims[k] as f64 - 0.5) * grid.spacing[k];
        lo[k] < first || hi[k] > last
    });
    if outside {
        eprintln!(
            "data-gen volume: warning: the shape sticks out of the grid and is cut off at its border"
        );
    }
    Ok(())
}

/// How errors name the surface: the shape, or the mesh file.
fn source_name(source: &TruthSource) -> String {
    match source {
        TruthSource::Shape(kind, _) => kind.name().to_string(),
        TruthSource::File(path) => path.display().to_string(),
    }
}

/// The command-line name of a format.
pub fn format_name(format: VolumeFormat) -> String {
    use clap::ValueEnum;
    format
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// Range checks of the scalar options (the grid checks its own).
fn check_scalars(args: &VolumeArgs) -> Result<()> {
    let finite = |name: &str, x: f64| -> Result<()> {
        if !x.is_finite() {
            bail!("{name} must be a finite number, got {x}");
        }
        Ok(())
    };
    finite("--inside", args.inside)?;
    finite("--outside", args.outside)?;
    if args.inside == args.outside {
        bail!(
            "--inside and --outside are both {}; the volume would be constant",
            args.inside
        );
    }
    for (name, x) in [
        ("--blur", args.blur),
        ("--noise", args.noise),
        ("--margin", args.margin),
    ] {
        if !(x.is_finite() && x >= 0.0) {
            bail!("{name} must be ≥ 0, got {x}");
        }
    }
    if !(0.0..1.0).contains(&args.inhomogeneity) {
        bail!(
            "--inhomogeneity must be in [0, 1), got {}",
            args.inhomogeneity
        );
    }
    if !(1..=16).contains(&args.supersample) {
        bail!("--supersample must be in 1..=16, got {}", args.supersample);
    }
    Ok(())
}

/// Parses `X,Y,Z` voxel counts.
fn parse_dims(s: &str) -> std::result::Result<[usize; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated counts X,Y,Z, got '{s}'"
        ));
    }
    let mut out = [0usize; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = p
            .parse()
            .map_err(|_| format!("'{p}' is not a voxel count (a whole number ≥ 1) in '{s}'"))?;
    }
    Ok(out)
}

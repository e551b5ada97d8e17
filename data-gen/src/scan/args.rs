//! `data-gen scan` options and their checks: [`ScanArgs`] from the command
//! line, [`ScanJob`] for a fully specified scan (also built by `demo`).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use serde_json::Value;
use subdyn::math::Real;

use super::ply::Precision;
use super::simulate::NormalKind;
use crate::shapes::ShapeKind;
use crate::sidecar::with_suffix;
use crate::truth::{ShapeOptions, TruthSource};

/// Options of `data-gen scan`.
#[derive(Args, Debug)]
pub struct ScanArgs {
    /// Built-in shape to scan.
    #[arg(value_enum, required_unless_present = "mesh", conflicts_with = "mesh")]
    pub shape: Option<ShapeKind>,
    /// Scan this mesh instead (OBJ, PLY, OFF; optionally .gz); it should be closed.
    #[arg(long, value_name = "FILE")]
    pub mesh: Option<PathBuf>,
    /// Output point cloud: binary PLY (.ply, or .ply.gz compressed). The sidecar
    /// goes to OUT with .json, the ground truth to OUT with .truth.obj.
    #[arg(short, long, value_name = "OUT.ply")]
    pub output: PathBuf,
    /// Number of views, on a Fibonacci sphere around the bounding-box centre.
    #[arg(long, default_value_t = 8, value_name = "N", conflicts_with = "poses")]
    pub views: usize,
    /// Read the views from JSON: [{"eye": [x,y,z], "target": [x,y,z], "up": [x,y,z]}, ...]
    /// (target defaults to the bounding-box centre, up is optional), or a scan sidecar.
    #[arg(long, value_name = "FILE")]
    pub poses: Option<PathBuf>,
    /// Parallel rays (window = bounding-box diagonal high).
    #[arg(long, conflicts_with = "perspective")]
    pub orthographic: bool,
    /// Rays from the eye through the pixels (the default).
    #[arg(long)]
    pub perspective: bool,
    /// Vertical field of view of the perspective sensor, degrees.
    #[arg(
        long,
        default_value_t = 40.0,
        value_name = "DEG",
        allow_negative_numbers = true
    )]
    pub fov: Real,
    /// Distance from the eyes to the bounding-box centre, in bounding-box
    /// diagonals (default: the object just fills the perspective view, 1 for orthographic).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub distance: Option<Real>,
    /// Pixels per view, across and down.
    #[arg(long, default_value = "160,120", value_name = "W,H", value_parser = parse_size)]
    pub resolution: (usize, usize),
    /// Gaussian range noise along each ray: σ = F × bounding-box diagonal.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "F",
        allow_negative_numbers = true
    )]
    pub noise: Real,
    /// Probability that a hit is lost.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "P",
        allow_negative_numbers = true
    )]
    pub dropout: Real,
    /// Fraction of the output points that are outliers (uniform in the
    /// bounding box enlarged by 10 % of its diagonal on every side).
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "P",
        allow_negative_numbers = true
    )]
    pub outliers: Real,
    /// Seed of every random stream; the same seed gives byte-identical files.
    #[arg(long, default_value_t = 0, value_name = "S")]
    pub seed: u64,
    /// Write no normals (real scanners estimate them).
    #[arg(long, conflicts_with = "smooth_normals")]
    pub no_normals: bool,
    /// Interpolated area-weighted vertex normals instead of the hit triangle's normal.
    #[arg(long)]
    pub smooth_normals: bool,
    /// Coordinate type in the PLY.
    #[arg(long, value_enum, default_value = "f64")]
    pub precision: Precision,
    /// Where to write the ground-truth mesh (default: OUT with .truth.obj).
    #[arg(long, value_name = "FILE")]
    pub truth: Option<PathBuf>,
    /// Resolution of a built-in shape (see `data-gen shape --help`).
    #[arg(long, value_name = "R")]
    pub shape_resolution: Option<usize>,
    #[command(flatten)]
    pub shape_options: ShapeOptions,
}

/// `"W,H"` as two positive integers.
fn parse_size(s: &str) -> std::result::Result<(usize, usize), String> {
    let err = || format!("expected W,H (two positive integers), got `{s}`");
    let (w, h) = s.split_once(',').ok_or_else(err)?;
    let w: usize = w.trim().parse().map_err(|_| err())?;
    let h: usize = h.trim().parse().map_err(|_| err())?;
    if w == 0 || h == 0 {
        return Err(err());
    }
    Ok((w, h))
}

/// A fully specified scan.
pub struct ScanJob {
    /// What to scan.
    pub source: TruthSource,
    /// Output PLY.
    pub output: PathBuf,
    /// Output ground-truth mesh.
    pub truth: PathBuf,
    /// Explicit poses (file), else `views` Fibonacci views.
    pub poses: Option<PathBuf>,
    /// Number of Fibonacci views.
    pub views: usize,
    /// Perspective (true) or orthographic.
    pub perspective: bool,
    /// Perspective field of view, degrees.
    pub fov: Real,
    /// Eye distance in diagonals.
    pub distance: Option<Real>,
    /// Pixels per view.
    pub resolution: (usize, usize),
    /// Noise as a fraction of the diagonal.
    pub noise: Real,
    /// Dropout probability.
    pub dropout: Real,
    /// Outlier fraction.
    pub outliers: Real,
    /// Seed.
    pub seed: u64,
    /// Normals.
    pub normals: NormalKind,
    /// PLY precision.
    pub precision: Precision,
    /// Extra facts for the sidecar (the demo's credits), merged at the top level.
    pub extra: Value,
}

impl ScanJob {
    /// The job described by command-line options.
    pub fn from_args(args: &ScanArgs) -> Result<ScanJob> {
        let source = match (&args.shape, &args.mesh) {
            (Some(kind), None) => {
                TruthSource::Shape(*kind, args.shape_options.params(args.shape_resolution))
            }
            (None, Some(path)) => TruthSource::File(path.clone()),
            _ => bail!("give a shape name or --mesh FILE"),
        };
        Ok(ScanJob {
            source,
            truth: args
                .truth
                .clone()
                .unwrap_or_else(|| with_suffix(&args.output, ".truth.obj")),
            output: args.output.clone(),
            poses: args.poses.clone(),
            views: args.views,
            perspective: !args.orthographic,
            fov: args.fov,
            distance: args.distance,
            resolution: args.resolution,
            noise: args.noise,
            dropout: args.dropout,
            outliers: args.outliers,
            seed: args.seed,
            normals: if args.no_normals {
                NormalKind::None
            } else if args.smooth_normals {
                NormalKind::Smooth
            } else {
                NormalKind::Face
            },
            precision: args.precision,
            extra: Value::Null,
        })
    }

    /// Checks every number before anything is computed.
    pub fn check(&self) -> Result<()> {
        if self.poses.is_none() && !(1..=10_000).contains(&self.views) {
            bail!("--views {} must be between 1 and 10000", self.views);
        }
        let (w, h) = self.resolution;
        if w == 0 || h == 0 || w.saturating_mul(h) > 16_777_216 {
            bail!("--resolution {w},{h}: each side must be positive and W×H at most 16777216");
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            bail!(
                "--noise {} must be a finite number ≥ 0 (a fraction of the bounding-box diagonal)",
                self.noise
            );
        }
        if !(0.0..1.0).contains(&self.dropout) {
            bail!("--dropout {} must be in [0, 1)", self.dropout);
        }
        if !(0.0..1.0).contains(&self.outliers) {
            bail!("--outliers {} must be in [0, 1)", self.outliers);
        }
        if !(self.fov > 0.0 && self.fov < 180.0) {
            bail!("--fov {} must be between 0 and 180 degrees", self.fov);
        }
        if let Some(d) = self.distance
            && !(d.is_finite() && d > 0.5)
        {
            bail!(
                "--distance {d} must exceed 0.5 diagonals (the eye must be outside the bounding sphere)"
            );
        }
        if !has_ply_extension(&self.output) {
            bail!(
                "{}: the scan is written as PLY; use a .ply or .ply.gz name",
                self.output.display()
            );
        }
        subdyn::io::MeshFormat::from_path(&self.truth)?;
        Ok(())
    }
}

fn has_ply_extension(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(".ply") || name.ends_with(".ply.gz")
}

//! `data-gen demo`: regenerates the demo data set embedded in subdyn
//! (`subdyn::examples::demo_scan`, `demo_truth`): an 8-view scan of Keenan
//! Crane's Spot with 0.1 % range noise.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use serde_json::json;

use crate::scan::{NormalKind, Precision, ScanJob, run_scan};
use crate::truth::TruthSource;

/// Options of `data-gen demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output directory (created if needed); the files are `spot_scan.ply.gz`,
    /// `spot_scan.json` and `spot_scan.truth.obj.gz`.
    #[arg(short, long, default_value = "data/demo", value_name = "DIR")]
    pub output: PathBuf,
    /// The mesh to scan: Keenan Crane's Spot (CC0).
    #[arg(
        long,
        default_value = "../shared/data/meshes/spot.obj",
        value_name = "FILE"
    )]
    pub source: PathBuf,
}

/// Views of the demo scan.
pub const VIEWS: usize = 8;
/// Pixels per view.
pub const RESOLUTION: (usize, usize) = (160, 120);
/// Range noise, fraction of the bounding-box diagonal.
pub const NOISE: f64 = 0.001;
/// Seed of the demo scan.
pub const SEED: u64 = 2024;

/// Runs `data-gen demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    if !args.source.exists() {
        bail!(
            "{}: not found; the demo scans Keenan Crane's Spot (../shared/data/meshes/spot.obj, run from the workspace root) — pass --source FILE",
            args.source.display()
        );
    }
    std::fs::create_dir_all(&args.output)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.output.display()))?;
    let job = ScanJob {
        source: TruthSource::File(args.source.clone()),
        output: args.output.join("spot_scan.ply.gz"),
        truth: args.output.join("spot_scan.truth.obj.gz"),
        poses: None,
        views: VIEWS,
        perspective: true,
        fov: 40.0,
        distance: None,
        resolution: RESOLUTION,
        noise: NOISE,
        dropout: 0.0,
        outliers: 0.0,
        seed: SEED,
        normals: NormalKind::Face,
        precision: Precision::F32,
        extra: json!({
            "data_set": "subdyn demo scan (subdyn::examples::demo_scan, demo_truth)",
            "credit": "Spot by Keenan Crane, https://www.cs.cmu.edu/~kmcrane/Projects/ModelRepository/ — public domain (CC0 1.0)",
            "regenerate": "cargo run --release -p data-gen -- demo   (from the workspace root)",
        }),
    };
    let record = run_scan(&job)?;
    println!(
        "{}: {} points from {} views of {}; ground truth {}",
        job.output.display(),
        record["counts"]["total"],
        VIEWS,
        args.source.display(),
        job.truth.display()
    );
    Ok(())
}

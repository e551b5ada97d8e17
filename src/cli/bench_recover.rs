//! `subdyn bench recover`: the stages of recovering a torus from an N³
//! volume (issue goals for 256³ on 2 cores: smoothing and force field under
//! 3 s, the whole recovery to 1-voxel accuracy under 20 s, memory under four
//! times the volume's f32 size).
//!
//! The volume is synthesised in memory: a torus (major radius 0.3 N, minor
//! 0.12 N voxels) as a partial-volume ramp `clamp(½ − sdf, 0, 1)` plus
//! Gaussian noise of standard deviation `--noise` (a fixed-seed generator),
//! 1 mm voxels. Accuracy is measured against the analytic distance on a
//! K = 4 limit tessellation.
//!
//! Memory: the peak resident size of every stage on its own
//! ([`super::memory`]: the kernel's high-water mark, reset before the stage),
//! against the volume's f32 size. The recovery's peak is the largest of
//! synthesis (the input volume, which a real run reads instead),
//! smoothing (in the input's own memory), initial cage and evolution; the
//! accuracy check's own
//! tessellation is reported apart.

use std::fmt::Write as _;
use std::time::Instant;

use clap::Args;
use serde_json::json;

use subdyn::fit::recover::{RecoverParams, component_cage, prepare_volume_owned, recover_shape};
use subdyn::forces::BoundaryModel;
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real};
use subdyn::subdivision::{RefineOptions, Refiner};
use subdyn::volume::Volume;

use super::common::{print_stdout, thousands};
use super::memory::{StagePeaks, current_rss, peak_rss, stage_peak};
use super::progress::Progress;

/// Arguments of `subdyn bench recover`.
#[derive(Debug, Args)]
pub struct BenchRecoverArgs {
    /// Voxels per side.
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub size: usize,
    /// Noise standard deviation (the torus is 1 inside, 0 outside).
    #[arg(long, value_name = "S", default_value_t = 0.1)]
    pub noise: f64,
    /// Recover the strongest edges instead of the 0.5 iso-surface.
    #[arg(long)]
    pub edges: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs the benchmark; the last stdout line is one JSON object.
pub fn bench_recover(args: &BenchRecoverArgs) -> anyhow::Result<()> {
    if !(16..=512).contains(&args.size) {
        anyhow::bail!("--size {} is out of range: expected 16 to 512", args.size);
    }
    if !(args.noise.is_finite() && (0.0..=1.0).contains(&args.noise)) {
        anyhow::bail!("--noise {} must be in [0, 1]", args.noise);
    }
    let progress = Progress::new(args.quiet);
    let n = args.size;
    let c = (n as Real - 1.0) / 2.0;
    let (big, small) = (0.3 * n as Real, 0.12 * n as Real);
    let sdf = move |p: &Point3| {
        let q = ((p.x - c).hypot(p.y - c) - big, p.z - c);
        q.0.hypot(q.1) - small
    };
    progress.stage(format!("synthesising a {n}³ torus volume"));
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut gauss = move || {
        // Box-Muller on a 64-bit LCG: reproducible, dependency-free.
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as Real + 0.5) / (1u64 << 53) as Real
        };
        let (u, v) = (uniform(), uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let d = sdf(&Point3::new(i as Real, j as Real, k as Real));
                data.push(((0.5 - d).clamp(0.0, 1.0) + args.noise * gauss()) as f32);
            }
        }
    }
    let volume = Volume::new([n; 3], data, [1.0; 3], Point3::origin())?;
    let volume_bytes = (n * n * n * 4) as u64;
    let synth_peak = peak_rss();
    let params = RecoverParams {
        boundary: if args.edges {
            BoundaryModel::Edge { min_strength: 0.1 }
        } else {
            BoundaryModel::Iso { value: 0.5 }
        },
        ..Default::default()
    };
    // Every stage's peak resident memory is measured on its own (reset of
    // the high-water mark before it). The input is smoothed in its own
    // memory and given up, as in `subdyn recover`.
    progress.stage("smoothing and force field");
    let (prepared, prepare_peak) = stage_peak(|| prepare_volume_owned(volume, &params));
    let prepared = prepared?;
    progress.stage("initial model");
    let t = Instant::now();
    let (cage, init_peak) = stage_peak(|| {
        component_cage(
            &prepared.smoothed,
            &prepared.smoothed,
            prepared.inside_level,
            true,
            None,
            24,
        )
    });
    let cage = cage?;
    let init_s = t.elapsed().as_secs_f64();
    let mut on_step = |level: usize, step: usize, _e: f64| {
        progress.stage(format!("level {level}, step {step}"));
    };
    let (result, evolution_peak) = stage_peak(|| {
        recover_shape(
            &prepared,
            &cage.mesh,
            &[],
            &cage.boundary,
            &params,
            &mut on_step,
        )
    });
    let result = result?;
    drop(progress);
    let evolution_s: f64 = result.report.levels.iter().map(|l| l.seconds).sum();
    let after_rss = current_rss();
    // The accuracy check below is the bench's own measurement, not part of
    // the recovery; its memory is reported separately.
    let (surf, check_peak) = stage_peak(|| -> anyhow::Result<_> {
        let refiner = Refiner::new(&result.control, &RefineOptions::default())?;
        Ok(tessellate(&refiner, &result.control.positions, 4)?.0)
    });
    let surf = surf?;
    let d: Vec<Real> = surf.positions.iter().map(|p| sdf(p).abs()).collect();
    let mean = d.iter().sum::<Real>() / d.len() as Real;
    let max = d.iter().cloned().fold(0.0, Real::max);
    let field_s = prepared.smoothing_seconds + prepared.potential_seconds;
    let total_s = field_s + init_s + evolution_s;
    let memory = StagePeaks {
        volume_bytes,
        stages: vec![
            ("synthesis", synth_peak),
            ("smoothing and force field", prepare_peak),
            ("initial cage", init_peak),
            ("evolution", evolution_peak),
        ],
    };
    let peak = memory.max();
    let mut text = String::new();
    writeln!(
        text,
        "recover bench: torus in a {n}³ volume (1 mm voxels, noise {}), {} boundary, {} threads",
        args.noise,
        if args.edges { "edge" } else { "iso 0.5" },
        rayon::current_num_threads()
    )?;
    writeln!(
        text,
        "smoothing {:.3} s + force field {:.3} s = {field_s:.3} s (goal < 3 s); initial cage {init_s:.3} s ({} control points, genus {})",
        prepared.smoothing_seconds,
        prepared.potential_seconds,
        thousands(cage.mesh.num_vertices()),
        cage.genus
    )?;
    for l in &result.report.levels {
        writeln!(
            text,
            "level {}: {} control points, {} samples, {} steps, {:.3} s, p95 offset {:.3} voxels",
            l.level,
            thousands(l.control_points),
            thousands(l.samples),
            l.steps,
            l.seconds,
            l.offsets.p95
        )?;
    }
    writeln!(
        text,
        "total {total_s:.2} s (goal < 20 s); distance to the true torus: mean {mean:.3}, max {max:.3} voxels (goal: 1 voxel)"
    )?;
    text.push_str(&memory.line());
    let mb = |b: Option<u64>| b.map_or("?".to_string(), |b| format!("{:.0}", b as f64 / 1e6));
    let ratio = peak.map(|p| memory.ratio(p));
    writeln!(
        text,
        "recovery peak {} MB = {} × the volume's f32 size (goal < 4 ×); accuracy check (not part of the recovery) {} MB; resident after the evolution {} MB",
        mb(peak),
        ratio.map_or("?".to_string(), |r| format!("{r:.2}")),
        mb(check_peak),
        mb(after_rss)
    )?;
    let record = json!({
        "bench": "recover",
        "size": n,
        "noise": args.noise,
        "boundary": if args.edges { "edge" } else { "iso" },
        "threads": rayon::current_num_threads(),
        "smoothing_s": prepared.smoothing_seconds,
        "force_field_s": prepared.potential_seconds,
        "init_s": init_s,
        "evolution_s": evolution_s,
        "total_s": total_s,
        "levels": result.report.levels.len(),
        "control_points": result.control.num_vertices(),
        "mean_distance_voxels": mean,
        "max_distance_voxels": max,
        "peak_memory_ratio": ratio,
        "peak_memory": memory.json(),
        "accuracy_check_peak_bytes": check_peak,
    });
    writeln!(text, "{record}")?;
    print_stdout(&text)
}

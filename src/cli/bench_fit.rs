//! `subdyn bench fit`: the main job, a range-scan fit, stage by stage —
//! initial cage, then per level its setup (patch table, stiffness, the
//! system's pattern), its implicit steps and the final error over every
//! point — as the median of `--repeat` runs, against the fitting issue's
//! goal of 2 s for a 30k-point scan on 2 cores.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use subdyn::fit::init::{InitParams, initial_mesh};
use subdyn::fit::{FitParams, FitReport, fit_screened_cloud};
use subdyn::io::read_points;

use super::common::{about_file, print_stdout, thousands, timed};
use super::progress::Progress;

/// The fitting issue's goal: seconds for a scan of about `GOAL_POINTS`
/// points (judged for scans within 20 % of that size).
const GOAL_SECONDS: f64 = 2.0;
const GOAL_POINTS: usize = 30_000;

/// Arguments of `subdyn bench fit`.
#[derive(Debug, Args)]
pub struct BenchFitArgs {
    /// Scan to fit (default: the embedded demo scan, Spot, 18,344 points).
    pub input: Option<PathBuf>,
    /// Runs; the median is reported.
    #[arg(long, value_name = "R", default_value_t = 3)]
    pub repeat: usize,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// One run: seconds of the initial cage and the fit's report.
struct Run {
    init_s: f64,
    fit_s: f64,
    report: FitReport,
}

/// Runs the benchmark; the last stdout line is one JSON object.
pub fn bench_fit(args: &BenchFitArgs) -> anyhow::Result<()> {
    if args.repeat == 0 || args.repeat > 100 {
        anyhow::bail!(
            "--repeat {} is out of range: expected 1 to 100",
            args.repeat
        );
    }
    let progress = Progress::new(args.quiet);
    progress.stage("reading the scan");
    let (cloud, read_s) = timed(|| match &args.input {
        Some(path) => read_points(path).map_err(|e| about_file(e, path)),
        None => Ok(subdyn::examples::demo_scan()?),
    });
    let cloud = cloud?;
    let name = args
        .input
        .as_ref()
        .map_or("the embedded demo scan".to_string(), |p| {
            p.display().to_string()
        });
    let mut runs = Vec::with_capacity(args.repeat);
    for r in 0..args.repeat {
        progress.stage(format!("run {} of {}", r + 1, args.repeat));
        let (init, init_s) = timed(|| initial_mesh(&cloud, &InitParams::default()));
        let (mesh, init) = init?;
        let (fit, fit_s) = timed(|| {
            fit_screened_cloud(
                &cloud,
                init.screening.as_ref(),
                &mesh,
                &FitParams::default(),
                &mut |_, _, _| {},
            )
        });
        runs.push(Run {
            init_s,
            fit_s,
            report: fit?.report,
        });
    }
    drop(progress);
    runs.sort_by(|a, b| (a.init_s + a.fit_s).total_cmp(&(b.init_s + b.fit_s)));
    let median = &runs[runs.len() / 2];
    let total = median.init_s + median.fit_s;
    let points = cloud.positions.len();
    let near_goal = (points as f64 - GOAL_POINTS as f64).abs() <= 0.2 * GOAL_POINTS as f64;
    let goal_met = near_goal.then_some(total <= GOAL_SECONDS);
    let mut out = String::new();
    writeln!(
        out,
        "fit of {name} ({} points), median of {} runs, {} threads",
        thousands(points),
        args.repeat,
        rayon::current_num_threads()
    )?;
    writeln!(
        out,
        "reading {read_s:.3} s (once); initial cage {:.3} s",
        median.init_s
    )?;
    writeln!(
        out,
        "level  control points  points used  setup s  steps  steps s  error s   p95 %"
    )?;
    let mut levels = Vec::new();
    for l in &median.report.levels {
        let steps_s = l.seconds - l.setup_seconds - l.error_seconds;
        writeln!(
            out,
            "{:>5}  {:>14}  {:>11}  {:>7.3}  {:>5}  {:>7.3}  {:>7.3}  {:>6.3}",
            l.level,
            thousands(l.control_points),
            thousands(l.points_used),
            l.setup_seconds,
            l.steps,
            steps_s,
            l.error_seconds,
            l.error.p95_pct
        )?;
        levels.push(json!({
            "level": l.level,
            "control_points": l.control_points,
            "points_used": l.points_used,
            "setup_s": l.setup_seconds,
            "steps": l.steps,
            "steps_s": steps_s,
            "error_s": l.error_seconds,
            "p95_pct": l.error.p95_pct,
        }));
    }
    let fastest = runs.first().map_or(total, |r| r.init_s + r.fit_s);
    writeln!(
        out,
        "initial cage + fit: {total:.3} s median, {fastest:.3} s fastest, {:.1} µs per point; \
         goal under {GOAL_SECONDS} s for a scan of about {} points: {}",
        1e6 * total / points as f64,
        thousands(GOAL_POINTS),
        match goal_met {
            Some(true) => "met",
            Some(false) => "not met",
            None => "not judged (the scan's size is too different)",
        }
    )?;
    let record = json!({
        "bench": "fit",
        "input": name,
        "points": points,
        "repeat": args.repeat,
        "threads": rayon::current_num_threads(),
        "read_s": read_s,
        "init_s": median.init_s,
        "fit_s": median.fit_s,
        "total_s": total,
        "fastest_total_s": fastest,
        "goal_s": GOAL_SECONDS,
        "goal_met": goal_met,
        "levels": levels,
        "stop_reason": median.report.stop_reason,
    });
    writeln!(out, "{record}")?;
    print_stdout(&out)
}

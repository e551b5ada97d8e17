//! `subdyn fit [SCAN] [--init MESH|auto] [--tol PCT] [--max-level L] -o FIT.obj`:
//! fit a dynamic Catmull-Clark surface to a point cloud (the main job).

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde_json::json;

use subdyn::fit::init::InitParams;
use subdyn::fit::{
    FitParams, FitReport, FitStart, Refinement, ToleranceStat, crease_options, fit_from_start,
    stat_name,
};
use subdyn::io::{read_points, write_control_mesh, write_mesh};
use subdyn::limit::limit_surface_mesh;
use subdyn::subdivision::{RefineOptions, Refiner};

use super::common::{
    Written, about_file, check_mesh_output, check_output_dir, seconds, thousands, warn,
    write_report,
};
use super::options::{LimitOutArgs, read_polygon_mesh};
use super::progress::Progress;

/// Which statistic `--tol` applies to.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TolStat {
    /// Largest distance (the paper's error).
    Max,
    /// 95th percentile.
    P95,
    /// Root mean square.
    Rms,
    /// Mean.
    Mean,
}

/// How a level above the tolerance is refined.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum RefineMode {
    /// Split only the faces whose data residual is above the noise (fewer
    /// control points, slower).
    Adaptive,
    /// Split every face (the paper's scheme).
    Uniform,
}

/// Arguments of `subdyn fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// Scan to fit (.ply, .xyz, .obj, .off; points, normals ignored). Without
    /// it, the embedded demo scan is fitted.
    #[arg(value_name = "SCAN")]
    pub input: Option<PathBuf>,
    /// Output control mesh; the format follows the extension.
    #[arg(short, long, value_name = "FIT", default_value = "fit.obj")]
    pub output: PathBuf,
    /// Initial control mesh: a mesh file, or a method: `auto` (an open grid
    /// for a single view, else the occupancy cage, or the principal-axes
    /// ellipsoid cage when that finds genus 0), `closed` (the ellipsoid cage),
    /// `open`, `occupancy`.
    #[arg(long, value_name = "MESH|METHOD", default_value = "auto")]
    pub init: String,
    /// Tolerance in % of the scan's bounding-box diagonal, on the distances of the points kept (outliers left out).
    #[arg(long, value_name = "PCT", default_value_t = 0.1)]
    pub tol: f64,
    /// Statistic the tolerance applies to.
    #[arg(long, value_enum, default_value_t = TolStat::P95)]
    pub tol_stat: TolStat,
    /// Subdivision levels allowed above the initial mesh.
    #[arg(long, value_name = "L", default_value_t = 3)]
    pub max_level: usize,
    /// How a level that settled above the tolerance is refined.
    #[arg(long, value_enum, default_value_t = RefineMode::Adaptive)]
    pub refine: RefineMode,
    /// Adaptive refinement splits a face when its mean squared data distance
    /// exceeds the noise variance by Z standard errors; lower splits more.
    #[arg(long, value_name = "Z", default_value_t = FitParams::default().refine_significance)]
    pub refine_significance: f64,
    /// Adaptive refinement also splits a face when one of its surface samples
    /// is farther from the data than F times the median such distance (a web
    /// across a gap the scan did not see into); 0 turns this off.
    #[arg(long, value_name = "F", default_value_t = FitParams::default().refine_off_data)]
    pub refine_off_data: f64,
    /// With `--tol-stat p95`, also stop when the 95th percentile is at most
    /// K times the noise σ estimated from the points (a perfect fit leaves
    /// 1.96 σ); 0 turns this off.
    #[arg(long, value_name = "K", default_value_t = FitParams::default().noise_tolerance)]
    pub noise_tol: f64,
    /// Tension weight λ_t of the thin plate (α = λ_t / area).
    #[arg(long, value_name = "λ", default_value_t = FitParams::default().tension)]
    pub tension: f64,
    /// Bending weight λ_b of the thin plate (β = λ_b / area).
    #[arg(long, value_name = "λ", default_value_t = FitParams::default().bending)]
    pub bending: f64,
    /// Fairness λ_u of the control net: the umbrella energy that keeps
    /// control points from spiking out and pleating the surface (λ_u / n per
    /// control point; 0 turns it off).
    #[arg(long, value_name = "λ", default_value_t = FitParams::default().fairness)]
    pub fairness: f64,
    /// Untangling rounds per level: where the limit surface crosses itself,
    /// smooth and stiffen the faces there and refit (0 turns it off).
    #[arg(long, value_name = "N", default_value_t = FitParams::default().untangle_rounds)]
    pub untangle_rounds: usize,
    /// Untangling rounds after the last level: where the limit surface
    /// still crosses itself, smooth the faces there without a refit, while
    /// the crossings get fewer (0 turns it off).
    #[arg(long, value_name = "N", default_value_t = FitParams::default().final_untangle_rounds)]
    pub final_untangle_rounds: usize,
    /// Sharp creases: after level 0, control edges along which the scan's
    /// two sides are flat and meet at this angle or more (degrees) are
    /// tagged infinitely sharp, kept if level 0 then fits no worse, and
    /// carried to the finer levels. An OBJ output carries them as `t
    /// crease` lines; other formats get OUTPUT.creases beside them (0 turns
    /// creases off).
    #[arg(long, value_name = "DEG", default_value_t = FitParams::default().crease_angle)]
    pub crease_angle: f64,
    /// Resolution of the automatic initial model: voxels along the longest
    /// axis of the occupancy cage, grid cells of the open grid. Holes and gaps
    /// narrower than about 4 voxels close up; raise it for thin gaps.
    #[arg(long, value_name = "N", default_value_t = InitParams::default().resolution)]
    pub init_resolution: usize,
    /// Mass μ/Δt² relative to the data weight: 0 integrates the first-order
    /// (massless) dynamics, above 0 the paper's second-order dynamics.
    #[arg(long, value_name = "μ", default_value_t = FitParams::default().mass)]
    pub mass: f64,
    #[command(flatten)]
    pub limit: LimitOutArgs,
    /// Write a JSON report (per level: control points, time, CG iterations, errors).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Write a PNG plot of the error (% of the diagonal, log scale) against
    /// time: per step the 95th percentile and RMS of the inliers the springs
    /// used, one colour per level; in black the table's 95th percentile over
    /// all points at the end of each level; the tolerance as a dashed line.
    #[arg(long, value_name = "P.png")]
    pub plot: Option<PathBuf>,
    /// No progress display and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `subdyn fit`.
pub fn run(args: &FitArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    check_mesh_output(&args.output)?;
    args.limit.check()?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if let Some(p) = &args.plot {
        subdyn::render::check_png_path(p)?;
    }
    let params = FitParams {
        tolerance_pct: args.tol,
        tolerance_stat: match args.tol_stat {
            TolStat::Max => ToleranceStat::Max,
            TolStat::P95 => ToleranceStat::P95,
            TolStat::Rms => ToleranceStat::Rms,
            TolStat::Mean => ToleranceStat::Mean,
        },
        max_level: args.max_level,
        refinement: match args.refine {
            RefineMode::Adaptive => Refinement::Adaptive,
            RefineMode::Uniform => Refinement::Uniform,
        },
        refine_significance: args.refine_significance,
        refine_off_data: args.refine_off_data,
        noise_tolerance: args.noise_tol,
        tension: args.tension,
        bending: args.bending,
        fairness: args.fairness,
        untangle_rounds: args.untangle_rounds,
        final_untangle_rounds: args.final_untangle_rounds,
        crease_angle: args.crease_angle,
        mass: args.mass,
        ..Default::default()
    };
    params.check()?;
    let progress = Progress::new(args.quiet);
    progress.stage("reading the scan");
    let (cloud, name) = match &args.input {
        Some(path) => (
            read_points(path).map_err(|e| about_file(e, path))?,
            path.display().to_string(),
        ),
        None => (
            subdyn::examples::demo_scan()?,
            "the embedded demo scan".to_string(),
        ),
    };
    progress.stage("building the initial model");
    let start_mesh = fit_start(&args.init, args.init_resolution, args.quiet)?;
    let levels = params.max_level as u64 + 1;
    let mut fit_progress = |level: usize, step: usize, energy: f64| {
        progress.counted(
            level as u64,
            levels,
            format!(
                "levels (at most) · level {level}, step {step} (≤ {}): energy {energy:.4e}",
                params.max_steps
            ),
        );
    };
    let mut run = fit_from_start(&cloud, &start_mesh, &params, &mut fit_progress)
        .map_err(|e| anyhow::Error::new(e).context(format!("fitting {name}")))?;
    if matches!(start_mesh, FitStart::Mesh(_)) {
        run.init_report["method"] = json!("file");
        run.init_report["path"] = json!(args.init);
    }
    let result = &run.result;
    progress.stage(format!("writing {}", args.output.display()));
    let crease_file = write_control_mesh(&args.output, &result.control, &result.creases)
        .map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(&args.output, "control mesh");
    if let Some(path) = &crease_file {
        written.add(
            path,
            "crease tags of the control mesh (--creases reads them)",
        );
    }
    if let Some(path) = &args.limit.limit_out {
        let (surf, normals) = limit_surface_mesh(
            &result.control,
            &crease_options(&result.creases),
            args.limit.tess,
            args.limit.faces.quads,
        )?;
        write_mesh(path, &surf, Some(&normals)).map_err(|e| about_file(e, path))?;
        written.add(path, "limit surface");
    }
    if let Some(path) = &args.plot {
        write_plot(path, &result.report, &params)?;
        written.add(path, "convergence plot");
    }
    drop(progress);
    if let Some(path) = &args.report {
        let mut value = json!({
            "command": "fit",
            "input": name,
            "output": args.output.display().to_string(),
            "limit_out": args.limit.limit_out.as_ref().map(|p| p.display().to_string()),
            "crease_file": crease_file.as_ref().map(|p| p.display().to_string()),
        });
        if let Some(map) = value.as_object_mut() {
            map.extend(run.report(&params)?);
            map.insert("total_s".into(), json!(seconds(start)));
        }
        write_report(path, &value)?;
        written.add(path, "report");
    }
    for w in &result.report.quality.warnings {
        warn(args.quiet, w);
    }
    written.print_after(&summary(&name, &result.report))
}

/// Error against time, one colour per level: per step the 95th percentile
/// and RMS of the points the springs used (inliers, subsampled on coarse
/// levels), and in black the table's 95th percentile over all points at the
/// end of each level; the tolerance as a dashed line. The title says which
/// set each is.
fn write_plot(path: &Path, report: &FitReport, params: &FitParams) -> anyhow::Result<()> {
    use subdyn::render::{HLine, PlotOptions, Series, line_plot, series_color, write_png};
    let n = report.levels.len();
    let mut series = Vec::new();
    for (i, l) in report.levels.iter().enumerate() {
        let pts = |v: &[f64]| -> Vec<(f64, f64)> {
            l.step_elapsed
                .iter()
                .copied()
                .zip(v.iter().map(|x| x.max(1e-9)))
                .collect()
        };
        let c = series_color(i, n);
        series.push(Series {
            label: format!("L{} p95", l.level),
            points: pts(&l.step_p95_pct),
            color: c,
        });
        let light = [c[0] / 2 + 127, c[1] / 2 + 127, c[2] / 2 + 127];
        series.push(Series {
            label: format!("L{} RMS", l.level),
            points: pts(&l.step_rms_pct),
            color: light,
        });
    }
    series.push(Series {
        label: "p95, kept points".into(),
        points: report
            .levels
            .iter()
            .map(|l| (l.elapsed, l.kept_error.p95_pct.max(1e-9)))
            .collect(),
        color: [0, 0, 0],
    });
    let title = format!(
        "fit error: colours = the inliers the springs used ({} outliers left out); black = all {} of them at the end of each level, as in the table",
        thousands(report.outliers),
        thousands(report.points - report.outliers)
    );
    let options = PlotOptions {
        title: Some(title),
        x_label: "seconds".into(),
        y_label: "distance, % of diagonal (log)".into(),
        log_y: true,
        hlines: vec![HLine {
            y: params.tolerance_pct,
            label: format!(
                "tolerance {} % ({})",
                params.tolerance_pct,
                stat_name(params.tolerance_stat)
            ),
            color: [200, 30, 30],
        }],
        width: 960,
        height: 540,
    };
    let pic = line_plot(&series, &options)?;
    write_png(path, &pic).map_err(|e| about_file(e, path))
}

/// Where the fit starts: a method name (`auto`, …), or a mesh file, read
/// and checked to be subdividable here so that its errors name the file.
fn fit_start(init: &str, resolution: usize, quiet: bool) -> anyhow::Result<FitStart> {
    if let Ok(kind) = init.parse::<subdyn::fit::init::InitKind>() {
        return Ok(FitStart::Method(InitParams {
            kind,
            resolution,
            ..Default::default()
        }));
    }
    let path = Path::new(init);
    let mesh = read_polygon_mesh(path, quiet)?;
    Refiner::new(&mesh, &RefineOptions::default()).map_err(|e| about_file(e, path))?;
    Ok(FitStart::Mesh(mesh))
}

fn summary(name: &str, r: &FitReport) -> String {
    let left_out = if r.outliers > 0 {
        format!(
            ", {} outliers left out of the springs",
            thousands(r.outliers)
        )
    } else {
        String::new()
    };
    let mut s = format!(
        "fitted {name} ({} points{left_out}) in {:.2} s: {}\n",
        thousands(r.points),
        r.seconds,
        r.stop_reason
    );
    s.push_str("level  control points  steps  CG its  seconds   max %   p95 %   RMS %  mean %  refinement\n");
    for l in &r.levels {
        s.push_str(&format!(
            "{:>5}  {:>14}  {:>5}  {:>6}  {:>7.2}  {:>6.3}  {:>6.3}  {:>6.3}  {:>6.3}  {}\n",
            l.level,
            thousands(l.control_points),
            l.steps,
            l.cg_iterations,
            l.seconds,
            l.kept_error.max_pct,
            l.kept_error.p95_pct,
            l.kept_error.rms_pct,
            l.kept_error.mean_pct,
            l.refinement
        ));
    }
    if r.outliers > 0 {
        s.push_str("errors are data-to-surface distances from the points kept (the outliers left out are not counted; the report's `error` counts them) in % of the scan's bounding-box diagonal\n");
    } else {
        s.push_str("errors are data-to-surface distances from all points in % of the scan's bounding-box diagonal\n");
    }
    s
}

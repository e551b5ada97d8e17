//! `subdyn bench closest`: the closest-point engine (the spring-force engine
//! of fitting) against a baseline measured in the same run — the nearest
//! vertex of a dense limit tessellation found with a k-d tree, which is what a
//! fitter without exact projection would use.

use std::fmt::Write as _;
use std::num::NonZero;
use std::path::PathBuf;

use clap::Args;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use serde_json::json;

use subdyn::limit::{ClosestPointEngine, ClosestPointParams, LimitEvaluator, tessellate};
use subdyn::math::{Point3, bbox_diagonal};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{RefineOptions, Refiner};

use super::common::{print_stdout, thousands, timed};
use super::options::read_polygon_mesh;
use super::progress::Progress;

/// Arguments of `subdyn bench closest`.
#[derive(Debug, Args)]
pub struct BenchClosestArgs {
    /// Control mesh (default: the embedded cube refined twice: 96 quads, 8 valence-3 vertices).
    pub input: Option<PathBuf>,
    /// Number of query points.
    #[arg(long, value_name = "N", default_value_t = 100_000)]
    pub queries: usize,
    /// Offset of the queries from the surface, as a fraction of the bounding-box diagonal.
    #[arg(long, value_name = "F", default_value_t = 0.005)]
    pub offset: f64,
    /// Tessellation rate of the baseline (K×K samples per quad).
    #[arg(long, value_name = "K", default_value_t = 8)]
    pub baseline_tess: usize,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs the benchmark; the last stdout line is one JSON object.
pub fn bench_closest(args: &BenchClosestArgs) -> anyhow::Result<()> {
    if args.queries == 0 || args.queries > 50_000_000 {
        anyhow::bail!(
            "--queries {} is out of range: expected 1 to 50,000,000",
            args.queries
        );
    }
    if !(args.offset.is_finite() && args.offset >= 0.0 && args.offset < 1.0) {
        anyhow::bail!(
            "--offset {} is out of range: expected 0 ≤ F < 1",
            args.offset
        );
    }
    if args.baseline_tess == 0 || args.baseline_tess > 64 {
        anyhow::bail!(
            "--baseline-tess {} is out of range: expected 1 to 64",
            args.baseline_tess
        );
    }
    let (mesh, name) = match &args.input {
        Some(path) => (
            read_polygon_mesh(path, args.quiet)?,
            path.display().to_string(),
        ),
        None => (embedded(), "embedded cube, refined twice".to_string()),
    };
    let progress = Progress::new(args.quiet);
    let refiner = Refiner::new(&mesh, &RefineOptions::default())?;
    let diag = bbox_diagonal(&mesh.positions);
    let offset = args.offset * diag;

    progress.stage("making queries");
    let eval = LimitEvaluator::new(&refiner);
    let queries = queries(&mesh, &eval, args.queries, offset)?;

    progress.stage("building the engine");
    let (engine, build_s) = timed(|| {
        ClosestPointEngine::new(&refiner, &mesh.positions, &ClosestPointParams::default())
    });
    let mut engine = engine?;
    progress.stage("querying");
    let (found, query_s) = timed(|| engine.closest_points(&queries));
    let found = found?;
    progress.stage("moving the control points");
    let moved: Vec<Point3> = mesh.positions.iter().map(|p| p * 1.01).collect();
    let (moved_ok, set_positions_s) = timed(|| engine.set_positions(&moved));
    moved_ok?;

    progress.stage("baseline: tessellation + k-d tree");
    let (baseline, baseline_build_s) = timed(|| -> anyhow::Result<_> {
        let (tess, _) = tessellate(&refiner, &mesh.positions, args.baseline_tess)?;
        let pts: Vec<[f64; 3]> = tess.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
        Ok((tess, ImmutableKdTree::<f64, 3>::new_from_slice(&pts)))
    });
    let (tess, tree) = baseline?;
    let one = NonZero::<usize>::MIN;
    let (base, baseline_query_s) = timed(|| -> Vec<f64> {
        queries
            .par_iter()
            .map(|q| {
                tree.nearest_n::<SquaredEuclidean>(&[q.x, q.y, q.z], one)[0]
                    .distance
                    .sqrt()
            })
            .collect()
    });
    drop(progress);

    // Each query was pushed `offset` out from a surface point, so the true
    // distance is at most `offset` (less where the surface is concave).
    let over = |d: f64| (d - offset).max(0.0) / diag;
    let engine_over = found.iter().map(|c| over(c.distance)).fold(0.0, f64::max);
    let baseline_over = base.iter().map(|&d| over(d)).fold(0.0, f64::max);
    let baseline_mean_gap: f64 = found
        .iter()
        .zip(&base)
        .map(|(c, &b)| (b - c.distance) / diag)
        .sum::<f64>()
        / found.len() as f64;
    let threads = rayon::current_num_threads();
    let n = queries.len() as f64;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "subdyn bench closest: {name}: {} control points, {} faces; {} queries {:.2e}·diag off the surface; {threads} threads",
        thousands(mesh.num_vertices()),
        thousands(mesh.num_faces()),
        thousands(queries.len()),
        args.offset
    );
    let _ = writeln!(text, "\n{:<44}{:>12}{:>14}", "", "seconds", "µs / query");
    let _ = writeln!(
        text,
        "{:<44}{:>12.4}",
        "engine build (patches, seeds, k-d tree)", build_s
    );
    let _ = writeln!(
        text,
        "{:<44}{:>12.4}{:>14.3}",
        "exact closest points",
        query_s,
        1e6 * query_s / n
    );
    let _ = writeln!(
        text,
        "{:<44}{:>12.4}",
        "set_positions (move the control mesh)", set_positions_s
    );
    let _ = writeln!(
        text,
        "{:<44}{:>12.4}",
        format!(
            "baseline build (tessellation K={}, k-d tree)",
            args.baseline_tess
        ),
        baseline_build_s
    );
    let _ = writeln!(
        text,
        "{:<44}{:>12.4}{:>14.3}",
        format!(
            "baseline: nearest of {} vertices",
            thousands(tess.num_vertices())
        ),
        baseline_query_s,
        1e6 * baseline_query_s / n
    );
    let _ = writeln!(
        text,
        "\nlargest distance beyond the known bound (·diag): engine {engine_over:.2e}, baseline {baseline_over:.2e}; \
         baseline is on average {baseline_mean_gap:.2e}·diag farther"
    );
    let summary = json!({
        "mesh": name,
        "control_points": mesh.num_vertices(),
        "faces": mesh.num_faces(),
        "queries": queries.len(),
        "threads": threads,
        "build_s": build_s,
        "query_s": query_s,
        "us_per_query": 1e6 * query_s / n,
        "set_positions_s": set_positions_s,
        "baseline_tess": args.baseline_tess,
        "baseline_vertices": tess.num_vertices(),
        "baseline_build_s": baseline_build_s,
        "baseline_query_s": baseline_query_s,
        "query_ratio": query_s / baseline_query_s,
        "max_excess_engine": engine_over,
        "max_excess_baseline": baseline_over,
        "baseline_mean_gap": baseline_mean_gap,
    });
    let _ = writeln!(text, "{summary}");
    print_stdout(&text)
}

/// The cube refined twice: a small control mesh with extraordinary vertices.
fn embedded() -> PolyMesh {
    let cube = subdyn::examples::cube();
    let refiner = Refiner::new(&cube, &RefineOptions::default()).expect("the cube is valid");
    let h = refiner.refine_uniform(2).expect("two levels");
    let p = h
        .stencil_to_level(2)
        .and_then(|s| s.apply(&cube.positions))
        .expect("sizes match");
    h.mesh(2, p)
}

/// Deterministic queries: limit samples at pseudo-random `(face, u, v)`,
/// pushed `±offset` along the normal.
fn queries(
    mesh: &PolyMesh,
    eval: &LimitEvaluator,
    n: usize,
    offset: f64,
) -> anyhow::Result<Vec<Point3>> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let picks: Vec<(usize, f64, f64, f64)> = (0..n)
        .map(|_| {
            let f = ((next() * mesh.num_faces() as f64) as usize).min(mesh.num_faces() - 1);
            let scale = if mesh.face(f).len() == 4 { 1.0 } else { 0.5 };
            let sign = if next() < 0.5 { -1.0 } else { 1.0 };
            (f, scale * next(), scale * next(), sign)
        })
        .collect();
    picks
        .par_iter()
        .map(|&(f, u, v, sign)| {
            let s = eval.evaluate(f, u, v, &mesh.positions)?;
            Ok(s.p + sign * offset * s.normal())
        })
        .collect()
}

//! `subdyn bench distance`: exact point-to-triangle-mesh distances with the
//! BVH of [`subdyn::metrics`] — build and query times — against brute force
//! (every triangle for every point) on a subsample measured in the same run.
//!
//! The mesh is an `n × m` quad torus (major radius 1, minor radius 0.35),
//! fan-triangulated, with `2nm ≈` `--triangles`. By default the points are
//! uniform in its bounding box grown by 10 % of the diagonal on every side:
//! most of them far off the surface, the hard case for branch and bound
//! (about a hundred triangles lie within a box bound of the answer). With
//! `--near F` they are points of the surface moved by up to `F` times the
//! diagonal along each axis, like a scan.

use std::fmt::Write as _;

use clap::Args;
use rayon::prelude::*;
use serde_json::json;

use subdyn::math::{Point3, Real, bbox_diagonal, bounding_box};
use subdyn::mesh::PolyMesh;
use subdyn::metrics::{TriangleBvh, area_samples, closest_point_on_triangle, distances};

use super::common::{print_stdout, thousands, timed};
use super::progress::Progress;

/// Arguments of `subdyn bench distance`.
#[derive(Debug, Args)]
pub struct BenchDistanceArgs {
    /// Number of query points.
    #[arg(long, value_name = "N", default_value_t = 1_000_000)]
    pub points: usize,
    /// Approximate number of triangles of the torus.
    #[arg(long, value_name = "M", default_value_t = 100_000)]
    pub triangles: usize,
    /// Points near the surface instead of uniform in the box: surface points
    /// moved by up to F × diagonal along each axis.
    #[arg(long, value_name = "F")]
    pub near: Option<f64>,
    /// Build and query runs; the fastest of each is reported.
    #[arg(long, value_name = "R", default_value_t = 1)]
    pub repeat: usize,
    /// Points of the brute-force subsample (default: about 2·10⁷ / M, at least 16).
    #[arg(long, value_name = "K")]
    pub brute: Option<usize>,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs the benchmark; the last stdout line is one JSON object.
pub fn bench_distance(args: &BenchDistanceArgs) -> anyhow::Result<()> {
    if args.points == 0 || args.points > 100_000_000 {
        anyhow::bail!(
            "--points {} is out of range: expected 1 to 100,000,000",
            args.points
        );
    }
    if args.triangles < 18 || args.triangles > 50_000_000 {
        anyhow::bail!(
            "--triangles {} is out of range: expected 18 to 50,000,000",
            args.triangles
        );
    }
    if args.repeat == 0 || args.repeat > 100 {
        anyhow::bail!(
            "--repeat {} is out of range: expected 1 to 100",
            args.repeat
        );
    }
    if let Some(f) = args.near
        && !(f.is_finite() && (0.0..1.0).contains(&f))
    {
        anyhow::bail!("--near {f} is out of range: expected 0 ≤ F < 1");
    }
    let progress = Progress::new(args.quiet);
    progress.stage("making the torus and the points");
    // Quads n × m with n ≈ 3m (the ratio of the two circumferences), 2nm ≈ M.
    let m = ((args.triangles as Real / 6.0).sqrt().round() as usize).max(3);
    let n = ((args.triangles as Real / (2.0 * m as Real)).round() as usize).max(3);
    let mesh = subdyn::examples::torus(n, m, 1.0, 0.35);
    let points = match args.near {
        None => random_points(&mesh.positions, args.points, 0.1),
        Some(f) => near_points(&mesh, args.points, f)?,
    };

    progress.stage("building the BVH");
    let mut build_s = Real::INFINITY;
    let mut bvh = None;
    for _ in 0..args.repeat {
        let (built, s) = timed(|| TriangleBvh::from_mesh(&mesh));
        build_s = build_s.min(s);
        bvh = Some(built?);
    }
    let bvh = bvh.ok_or_else(|| anyhow::anyhow!("no BVH was built"))?;
    let triangles = bvh.triangles().len();
    progress.stage("querying");
    let mut query_s = Real::INFINITY;
    let mut found = Vec::new();
    for _ in 0..args.repeat {
        let (f, s) = timed(|| distances(&bvh, &points));
        query_s = query_s.min(s);
        found = f?;
    }

    progress.stage("brute force on a subsample");
    let brute_n = args
        .brute
        .unwrap_or((2e7 / triangles as Real) as usize)
        .clamp(16.min(args.points), args.points);
    let step = args.points / brute_n;
    let sample: Vec<usize> = (0..brute_n).map(|i| i * step).collect();
    let (brute, brute_s) = timed(|| -> Vec<Real> {
        sample
            .par_iter()
            .map(|&i| brute_force(&bvh, points[i]))
            .collect()
    });
    drop(progress);
    let max_diff = sample
        .iter()
        .zip(&brute)
        .map(|(&i, &d)| (found[i].distance - d).abs())
        .fold(0.0, Real::max);
    let per_point = query_s / args.points as Real;
    let brute_per_point = brute_s / brute_n as Real;
    let speedup = brute_per_point / per_point;
    let threads = rayon::current_num_threads();
    let mean = found.iter().map(|f| f.distance).sum::<Real>() / found.len() as Real;

    let mut text = String::new();
    let _ = writeln!(
        text,
        "subdyn bench distance: {n}×{m} torus, {} triangles, {} BVH nodes (4-wide); {} points {}; {threads} threads{}",
        thousands(triangles),
        thousands(bvh.num_nodes()),
        thousands(args.points),
        match args.near {
            None => "uniform in the box grown by 10 %".to_string(),
            Some(f) => format!("within {f}·diagonal of the surface"),
        },
        if args.repeat > 1 {
            format!("; best of {}", args.repeat)
        } else {
            String::new()
        }
    );
    let _ = writeln!(text, "\n{:<40}{:>12}{:>14}", "", "seconds", "µs / point");
    let _ = writeln!(text, "{:<40}{build_s:>12.4}", "BVH build (binned SAH)");
    let _ = writeln!(
        text,
        "{:<40}{query_s:>12.4}{:>14.4}",
        "exact distances (BVH)",
        1e6 * per_point
    );
    let _ = writeln!(
        text,
        "{:<40}{:>12.4}",
        "total (build + queries)",
        build_s + query_s
    );
    let _ = writeln!(
        text,
        "{:<40}{brute_s:>12.4}{:>14.2}",
        format!("brute force, {} points", thousands(brute_n)),
        1e6 * brute_per_point
    );
    let _ = writeln!(
        text,
        "\nBVH is {speedup:.0}× faster per point than brute force; max |BVH − brute| = {max_diff:.1e}; mean distance {mean:.4}"
    );
    let line = json!({
        "build_s": build_s,
        "query_s": query_s,
        "total_s": build_s + query_s,
        "points": args.points,
        "distribution": match args.near {
            None => "box".to_string(),
            Some(f) => format!("near {f}"),
        },
        "repeat": args.repeat,
        "triangles": triangles,
        "nodes": bvh.num_nodes(),
        "threads": threads,
        "us_per_point": 1e6 * per_point,
        "brute_points": brute_n,
        "brute_s": brute_s,
        "brute_us_per_point": 1e6 * brute_per_point,
        "speedup_vs_brute": speedup,
        "max_abs_diff_vs_brute": max_diff,
        "mean_distance": mean,
    });
    let _ = writeln!(text, "{line}");
    print_stdout(&text)
}

/// Distance from `q` to the nearest of all triangles, one by one.
fn brute_force(bvh: &TriangleBvh, q: Point3) -> Real {
    let p = bvh.positions();
    bvh.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| p[v as usize]);
            (closest_point_on_triangle(q, a, b, c).0 - q).norm_squared()
        })
        .fold(Real::INFINITY, Real::min)
        .sqrt()
}

/// `n` deterministic points: samples of `mesh`'s surface moved by a
/// uniform offset in `[-f, f]³ · diagonal`.
fn near_points(mesh: &PolyMesh, n: usize, f: Real) -> anyhow::Result<Vec<Point3>> {
    let bvh = TriangleBvh::from_mesh(mesh)?;
    let samples = area_samples(bvh.positions(), bvh.triangles(), n, 7)?;
    let offsets = random_points(
        &[Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0)],
        n,
        0.0,
    );
    let scale = f * bbox_diagonal(&mesh.positions);
    Ok(samples
        .iter()
        .zip(&offsets)
        .map(|((p, _), o)| p + o.coords * scale)
        .collect())
}

/// `n` deterministic points uniform in the bounding box of `positions`
/// grown by `margin` times its diagonal on every side.
fn random_points(positions: &[Point3], n: usize, margin: Real) -> Vec<Point3> {
    let (lo, hi) = bounding_box(positions).unwrap_or((Point3::origin(), Point3::origin()));
    let pad = margin * (hi - lo).norm();
    let lo = lo.map(|c| c - pad);
    let size = (hi - lo).map(|c| c + pad);
    (0..n as u64)
        .into_par_iter()
        .map(|i| {
            let mut s = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
            let mut next = || {
                s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = s;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                z ^= z >> 31;
                (z >> 11) as Real / (1u64 << 53) as Real
            };
            Point3::new(
                lo.x + size.x * next(),
                lo.y + size.y * next(),
                lo.z + size.z * next(),
            )
        })
        .collect()
}

//! `subdyn compare A B [--report R.json]`: distances from `A` (a mesh or a
//! point file) to the reference mesh `B` — one-sided statistics both ways,
//! Chamfer, Hausdorff and normal consistency, absolute and in percent of
//! `B`'s bounding-box diagonal. Every definition is in
//! [`subdyn::metrics::compare`](subdyn::metrics::compare()) and in the report.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde_json::{Value, json};

use subdyn::io::{MeshFormat, atomic_write, read_mesh_from_bytes, read_points_from_bytes};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::metrics::{CompareParams, Comparison, OneSided, Surface, compare, compare_points};
use subdyn::subdivision::RefineOptions;

use super::common::{
    Written, about_file, bbox_json, check_output_dir, seconds, thousands, timed, write_report,
};
use super::options::{Boundary, read_polygon_mesh, warn_isolated};
use super::progress::Progress;
use super::subdivide::MAX_FACES;

/// Largest `--samples` accepted.
const MAX_SAMPLES: usize = 100_000_000;
/// Bytes held per sample (points, distances, closest points and the sorted
/// copies of both directions; measured: about 240 B at 10⁶ and 4·10⁶).
const BYTES_PER_SAMPLE: u64 = 260;

/// Arguments of `subdyn compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The mesh or point file to measure (.obj, .ply, .off, .xyz, optionally
    /// .gz); a file without faces is a point cloud (then `A → B` only).
    #[arg(value_name = "A")]
    pub a: PathBuf,
    /// The reference mesh (must have faces); percentages are of its
    /// bounding-box diagonal.
    #[arg(value_name = "B")]
    pub b: PathBuf,
    /// Write every figure, the definitions and the timings as JSON.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Area-weighted sample points per surface; their distances give mean,
    /// RMS and percentiles, the vertices are added for the maximum. 0: the
    /// vertices alone.
    #[arg(long, value_name = "N", default_value_t = 100_000)]
    pub samples: usize,
    /// Seed of the sample positions.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Measure A's Catmull-Clark limit surface instead of the mesh itself
    /// (exact projection; A must be a polygon mesh).
    #[arg(long)]
    pub limit_a: bool,
    /// Measure B's Catmull-Clark limit surface instead of the mesh itself.
    #[arg(long)]
    pub limit_b: bool,
    /// Tessellation rate (K×K per quad; n-gons count as n quads) on which
    /// limit-surface samples are drawn before being projected onto the limit
    /// surface. Default: the smallest K giving at least as many quads as
    /// samples / 2 (at most 16).
    #[arg(long, value_name = "K")]
    pub limit_rate: Option<usize>,
    /// Boundary rule of the limit surfaces.
    #[arg(long, value_enum, default_value_t = Boundary::EdgeAndCorner)]
    pub boundary: Boundary,
    /// Write one line `x y z d` per A → B query point (A's points, or its
    /// samples) with its distance d to B, in query order.
    #[arg(long, value_name = "FILE")]
    pub distances_out: Option<PathBuf>,
    /// No progress display and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// What was read from `A`.
enum Side {
    Mesh(PolyMesh),
    Points(PointCloud),
}

/// Runs `subdyn compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if let Some(p) = &args.distances_out {
        check_output_dir(p)?;
    }
    if args.samples > MAX_SAMPLES {
        anyhow::bail!(
            "--samples {} is out of range: expected 0 to {}",
            args.samples,
            thousands(MAX_SAMPLES)
        );
    }
    subdyn::memory::check_memory(
        &format!("--samples {}", thousands(args.samples)),
        subdyn::memory::bytes_of(args.samples as u64, BYTES_PER_SAMPLE),
    )?;
    if let Some(k) = args.limit_rate
        && (k == 0 || k > 64)
    {
        anyhow::bail!("--limit-rate {k} is out of range: expected 1 to 64");
    }
    let progress = Progress::new(args.quiet);
    progress.stage("reading the meshes");
    let (read, read_s) = timed(|| -> anyhow::Result<_> {
        let a = read_side(&args.a, args.quiet)?;
        let b = read_polygon_mesh(&args.b, args.quiet)?;
        Ok((a, b))
    });
    let (a, b) = read?;
    if args.limit_a && matches!(a, Side::Points(_)) {
        anyhow::bail!(
            "{}: --limit-a needs a polygon mesh, but the file has points only",
            args.a.display()
        );
    }

    progress.stage("building the BVH / limit surfaces");
    let options = RefineOptions {
        boundary: args.boundary.rule(),
        ..RefineOptions::default()
    };
    let surface = |mesh: &PolyMesh, limit: bool, path: &Path| -> anyhow::Result<Surface> {
        if limit {
            let rate = limit_rate(mesh, args);
            check_tessellation(mesh, rate, path)?;
            Surface::limit(mesh, &options, rate).map_err(|e| about_file(e, path))
        } else {
            Surface::mesh(mesh).map_err(|e| about_file(e, path))
        }
    };
    let (built, build_s) = timed(|| -> anyhow::Result<_> {
        let sb = surface(&b, args.limit_b, &args.b)?;
        let sa = match &a {
            Side::Mesh(mesh) => Some(surface(mesh, args.limit_a, &args.a)?),
            Side::Points(_) => None,
        };
        Ok((sa, sb))
    });
    let (sa, sb) = built?;

    progress.stage("measuring distances");
    let params = CompareParams {
        samples: args.samples,
        seed: args.seed,
    };
    let (result, compare_s) = timed(|| match (&a, &sa) {
        (Side::Points(cloud), _) => compare_points(&cloud.positions, cloud.normals.as_deref(), &sb),
        (Side::Mesh(_), Some(sa)) => compare(sa, &sb, &params),
        (Side::Mesh(_), None) => Err(subdyn::Error::input("no surface for A")),
    });
    let c = result?;
    drop(progress);

    let mut written = Written::new();
    if let Some(path) = &args.distances_out {
        write_distances(path, &c.a_to_b)?;
        written.add(path, "distances A to B");
    }
    let total_s = seconds(start);
    let text = table(args, &a, &b, &c);
    if let Some(path) = &args.report {
        let mut report = serde_json::to_value(&c)?;
        report["a"] = side_json(&args.a, &a, args.limit_a);
        report["b"] = mesh_json(&args.b, &b, args.limit_b);
        report["samples"] = json!(args.samples);
        report["seed"] = json!(args.seed);
        report["limit_rate"] = json!({
            "a": (args.limit_a).then(|| match &a { Side::Mesh(m) => limit_rate(m, args), Side::Points(_) => 0 }),
            "b": (args.limit_b).then(|| limit_rate(&b, args)),
        });
        report["definitions"] = definitions();
        report["distances_out"] =
            json!(args.distances_out.as_ref().map(|p| p.display().to_string()));
        report["timings_s"] = json!({
            "read": read_s, "build": build_s, "compare": compare_s, "total": total_s,
        });
        write_report(path, &report)?;
        written.add(path, "report");
    }
    written.print_after(&text)
}

/// Reads `A`: a polygon mesh, or (no faces) a point cloud with its normals.
fn read_side(path: &Path, quiet: bool) -> anyhow::Result<Side> {
    let format = MeshFormat::from_path(path).map_err(|e| about_file(e, path))?;
    let bytes = subdyn::io::read_input(path)?;
    let mesh = read_mesh_from_bytes(&bytes, format, path).map_err(|e| about_file(e, path))?;
    if mesh.num_faces() > 0 {
        warn_isolated(&mesh, &path.display().to_string(), quiet);
        return Ok(Side::Mesh(mesh));
    }
    let cloud = read_points_from_bytes(&bytes, format, path).map_err(|e| about_file(e, path))?;
    Ok(Side::Points(cloud))
}

/// `--limit-rate`, or the smallest K with `quads · K² ≥ samples / 2` (1 to 16).
fn limit_rate(mesh: &PolyMesh, args: &CompareArgs) -> usize {
    args.limit_rate.unwrap_or_else(|| {
        let quads = quads(mesh).max(1) as f64;
        ((args.samples as f64 / 2.0 / quads).sqrt().ceil() as usize).clamp(1, 16)
    })
}

/// Quads of the limit tessellation at rate 1: n-gons split into n quads.
fn quads(mesh: &PolyMesh) -> usize {
    mesh.faces()
        .map(|f| if f.len() == 4 { 1 } else { f.len() })
        .sum()
}

/// Fails when the limit tessellation of `mesh` at `rate` would be too large.
fn check_tessellation(mesh: &PolyMesh, rate: usize, path: &Path) -> anyhow::Result<()> {
    let quads: usize = mesh
        .faces()
        .map(|f| if f.len() == 4 { 1 } else { f.len() })
        .sum();
    let faces = quads as f64 * (rate * rate) as f64;
    if faces > MAX_FACES as f64 {
        anyhow::bail!(
            "{}: --limit-rate {rate} would tessellate about {} faces (at most {} allowed)",
            path.display(),
            thousands(faces as usize),
            thousands(MAX_FACES)
        );
    }
    Ok(())
}

/// `x y z d` lines, shortest round-trip numbers, written atomically.
fn write_distances(path: &Path, side: &OneSided) -> anyhow::Result<()> {
    atomic_write(path, |w| {
        for (q, d) in side.queries.iter().zip(&side.distances) {
            writeln!(w, "{} {} {} {d:e}", q.x, q.y, q.z)?;
        }
        Ok(())
    })
    .map_err(|e| anyhow::Error::new(e).context("cannot write the distances"))
}

fn mesh_json(path: &Path, mesh: &PolyMesh, limit: bool) -> Value {
    json!({
        "file": path.display().to_string(),
        "kind": if limit { "limit surface" } else { "mesh" },
        "vertices": mesh.num_vertices(),
        "faces": mesh.num_faces(),
        "bbox": bbox_json(&mesh.positions),
    })
}

fn side_json(path: &Path, side: &Side, limit: bool) -> Value {
    match side {
        Side::Mesh(mesh) => mesh_json(path, mesh, limit),
        Side::Points(cloud) => json!({
            "file": path.display().to_string(),
            "kind": "points",
            "points": cloud.len(),
            "normals": cloud.normals.is_some(),
            "bbox": bbox_json(&cloud.positions),
        }),
    }
}

fn definitions() -> Value {
    json!({
        "distance": "exact Euclidean distance from a query point to the nearest point of the other surface (BVH over its triangles; exact projection for a limit surface)",
        "queries": "area-weighted samples on the surface (systematic over triangle areas, uniform inside each triangle); the surface's vertices are queried too, for max only; a point cloud's queries are its points; with --samples 0 the vertices alone",
        "mean_rms": "mean and root mean square of the query distances",
        "percentiles": "nearest rank: P_p is the ceil(p n / 100)-th smallest query distance (median = P_50, p95 = P_95)",
        "max": "largest distance over the queries and the vertices (one-sided Hausdorff)",
        "chamfer": "(mean A->B + mean B->A) / 2; for a point cloud A, the one-sided mean A->B",
        "hausdorff": "max(max A->B, max B->A); for a point cloud A, the one-sided max A->B",
        "normal_consistency": "mean |n_x . n_y| over queries with a normal, n_x at the query, n_y at its closest point (face or limit normals); symmetric figure = mean of the two directions",
        "percent": "100 * figure / diagonal, diagonal = bounding-box diagonal of B (of its limit tessellation with --limit-b)",
    })
}

/// The readable summary.
fn table(args: &CompareArgs, a: &Side, b: &PolyMesh, c: &Comparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "A: {}  {}", args.a.display(), describe(a, args.limit_a));
    let _ = writeln!(
        s,
        "B: {}  {}  reference, bounding-box diagonal {}",
        args.b.display(),
        describe_mesh(b, args.limit_b),
        num(c.diagonal)
    );
    let queries = match a {
        Side::Points(_) => "A's points".to_string(),
        Side::Mesh(_) if args.samples == 0 => "vertices only".to_string(),
        Side::Mesh(_) => format!(
            "{} area-weighted samples per surface (vertices added for max)",
            thousands(args.samples)
        ),
    };
    let _ = writeln!(s, "queries: {queries}\n");
    let _ = write!(s, "{:<20}{:>14}{:>12}", "", "A → B", "% diag");
    if c.b_to_a.is_some() {
        let _ = write!(s, "{:>14}{:>12}", "B → A", "% diag");
    }
    let _ = writeln!(s);
    type Pick = fn(&OneSided) -> (f64, f64);
    let rows: [(&str, Pick); 6] = [
        ("mean", |o| (o.stats.mean, o.stats_pct.mean)),
        ("rms", |o| (o.stats.rms, o.stats_pct.rms)),
        ("median", |o| (o.stats.median, o.stats_pct.median)),
        ("95th percentile", |o| (o.stats.p95, o.stats_pct.p95)),
        ("max", |o| (o.max, o.max_pct)),
        ("min", |o| (o.stats.min, o.stats_pct.min)),
    ];
    for (name, pick) in rows {
        let (x, p) = pick(&c.a_to_b);
        let _ = write!(s, "{name:<20}{:>14}{:>12}", num(x), num(p));
        if let Some(ba) = &c.b_to_a {
            let (x, p) = pick(ba);
            let _ = write!(s, "{:>14}{:>12}", num(x), num(p));
        }
        let _ = writeln!(s);
    }
    let nc = |o: &OneSided| {
        o.normal_consistency
            .map_or("-".to_string(), |v| format!("{v:.5}"))
    };
    let _ = write!(
        s,
        "{:<20}{:>14}{:>12}",
        "normal consistency",
        nc(&c.a_to_b),
        ""
    );
    if let Some(ba) = &c.b_to_a {
        let _ = write!(s, "{:>14}", nc(ba));
    }
    let _ = writeln!(s, "\n");
    let (ch, hd) = if c.symmetric {
        ("Chamfer ½(mean A→B + mean B→A)", "Hausdorff max(A→B, B→A)")
    } else {
        (
            "one-sided Chamfer (mean A→B)",
            "one-sided Hausdorff (max A→B)",
        )
    };
    let _ = writeln!(
        s,
        "{ch:<34}{:>14} {:>11} %",
        num(c.chamfer),
        num(c.chamfer_pct)
    );
    let _ = writeln!(
        s,
        "{hd:<34}{:>14} {:>11} %",
        num(c.hausdorff),
        num(c.hausdorff_pct)
    );
    if c.symmetric
        && let Some(v) = c.normal_consistency
    {
        let _ = writeln!(s, "{:<34}{v:>14.5}", "normal consistency (both ways)");
    }
    s
}

/// `mesh (8 vertices, 6 faces)` or `points (1,000, with normals)`.
fn describe(side: &Side, limit: bool) -> String {
    match side {
        Side::Mesh(m) => describe_mesh(m, limit),
        Side::Points(p) => format!(
            "points ({}{})",
            thousands(p.len()),
            if p.normals.is_some() {
                ", with normals"
            } else {
                ""
            }
        ),
    }
}

fn describe_mesh(m: &PolyMesh, limit: bool) -> String {
    format!(
        "{} ({} vertices, {} faces)",
        if limit { "limit surface of" } else { "mesh" },
        thousands(m.num_vertices()),
        thousands(m.num_faces())
    )
}

/// Five significant digits, scientific outside `[1e-3, 1e5)`.
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&x.abs()) {
        let digits = (4 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.4e}")
    }
}

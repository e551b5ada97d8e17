//! `subdyn bench ffd`: free-form deformation with an automatic octree
//! lattice around a 50k-vertex model (the multiresolution-lattice paper's
//! setting: 53,417 vertices, one control point moved per frame).
//!
//! Stages, timed separately: building the lattice (box, octree levels,
//! culling), refining it `n` times (topology and `S_n`), embedding the
//! vertices and forming `B = W S_n`; then moving one control point — the
//! local update through the column of `B` — against recomputing every vertex
//! with the full product `B p`, both measured in the same run. Last, the
//! memory of the topology of a 32³-cell lattice, counted array by array:
//! the 4³ box refined three times (the refined lattice of the paper's 20 MB
//! figure) with every incidence, the same level in the compact form the FFD
//! builds (type-n cells and boundary quads), and a 32³ box grid built
//! directly.
//!
//! The model is an `n × m` quad torus (major radius 1, minor radius 0.35).

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Instant;

use clap::Args;
use serde_json::json;

use subdyn::ffd::Ffd;
use subdyn::lattice::{BoxLatticeParams, LatticeHierarchy, box_grid, box_lattice, refined_cells};
use subdyn::math::{Point3, Real, Vector3};

use super::common::{print_stdout, thousands, timed};
use super::ffd::embedding_stage;
use super::progress::Progress;

/// Arguments of `subdyn bench ffd`.
#[derive(Debug, Args)]
pub struct BenchFfdArgs {
    /// Approximate number of model vertices (a quad torus).
    #[arg(long, value_name = "N", default_value_t = 50_000)]
    pub vertices: usize,
    /// Octree levels K of the automatic lattice (2^K cells per axis before culling).
    #[arg(long, value_name = "K", default_value_t = 2)]
    pub octree_levels: usize,
    /// Catmull-Clark refinement levels n of the lattice for the embedding.
    #[arg(long, value_name = "L", default_value_t = 3)]
    pub levels: usize,
    /// Single-point updates timed (their mean is reported).
    #[arg(long, value_name = "U", default_value_t = 2000)]
    pub updates: usize,
    /// Embedding runs; the fastest is reported.
    #[arg(long, value_name = "R", default_value_t = 1)]
    pub repeat: usize,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs the benchmark; the last stdout line is one JSON object.
pub fn bench_ffd(args: &BenchFfdArgs) -> anyhow::Result<()> {
    if !(100..=20_000_000).contains(&args.vertices) {
        anyhow::bail!(
            "--vertices {} is out of range: expected 100 to 20,000,000",
            args.vertices
        );
    }
    if args.octree_levels > 5 {
        anyhow::bail!(
            "--octree-levels {} is out of range: expected 0 to 5",
            args.octree_levels
        );
    }
    if !(1..=4).contains(&args.levels) {
        anyhow::bail!("--levels {} is out of range: expected 1 to 4", args.levels);
    }
    if !(1..=10_000_000).contains(&args.updates) {
        anyhow::bail!(
            "--updates {} is out of range: expected 1 to 10,000,000",
            args.updates
        );
    }
    if !(1..=100).contains(&args.repeat) {
        anyhow::bail!(
            "--repeat {} is out of range: expected 1 to 100",
            args.repeat
        );
    }
    let progress = Progress::new(args.quiet);
    progress.stage("making the torus");
    // n × m quads with n ≈ 3m (the ratio of the two circumferences), nm ≈ N.
    let m = ((args.vertices as Real / 3.0).sqrt().round() as usize).max(3);
    let n = ((args.vertices as Real / m as Real).round() as usize).max(3);
    let model = subdyn::examples::torus(n, m, 1.0, 0.35);
    let points = &model.positions;

    progress.stage("building the octree lattice");
    let lattice_params = BoxLatticeParams {
        octree_levels: args.octree_levels,
        ..Default::default()
    };
    let (lattice, lattice_s) = timed(|| box_lattice(points, &lattice_params));
    let lattice = lattice?;

    let params = embedding_stage(&progress, args.levels);
    let mut best: Option<Ffd> = None;
    let (mut refine_s, mut embed_s) = (Real::INFINITY, Real::INFINITY);
    for _ in 0..args.repeat {
        let ffd = Ffd::new(&lattice, points, &params)?;
        if ffd.report.refine_s + ffd.report.embed_s < refine_s + embed_s {
            refine_s = ffd.report.refine_s;
            embed_s = ffd.report.embed_s;
        }
        best = Some(ffd);
    }
    let mut ffd = best.ok_or_else(|| anyhow::anyhow!("no embedding was made"))?;
    let rest_control = ffd.control.clone();

    progress.stage("moving one control point");
    // The control point whose column of B is largest: the worst single move.
    let moved = (0..ffd.bt.num_rows())
        .max_by_key(|&c| ffd.bt.row(c).0.len())
        .unwrap_or(0);
    let column = ffd.bt.row(moved).0.len();
    let size = subdyn::math::bbox_diagonal(&rest_control);
    let offset = |i: usize| {
        let t = i as Real * 0.37;
        Vector3::new(t.cos(), t.sin(), (2.0 * t).cos()) * (0.05 * size)
    };
    let start = Instant::now();
    let mut touched = 0;
    for i in 0..args.updates {
        touched = ffd.move_control(&[(moved, rest_control[moved] + offset(i))])?;
        black_box(&ffd.deformed);
    }
    let local_s = start.elapsed().as_secs_f64() / args.updates as Real;
    // The same moves by the full product, fewer of them (each is a whole pass).
    let full_runs = args.updates.clamp(1, 200);
    let mut control = rest_control.clone();
    let start = Instant::now();
    for i in 0..full_runs {
        control[moved] = rest_control[moved] + offset(i);
        ffd.set_control(&control)?;
        black_box(&ffd.deformed);
    }
    let full_s = start.elapsed().as_secs_f64() / full_runs as Real;
    // The local path must agree with the full product.
    ffd.set_control(&rest_control)?;
    let q = rest_control[moved] + offset(7);
    ffd.move_control(&[(moved, q)])?;
    let local = ffd.deformed.clone();
    control.copy_from_slice(&rest_control);
    control[moved] = q;
    let full = ffd.deform(&control)?;
    let max_diff = local
        .iter()
        .zip(&full)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, Real::max);

    progress.stage("measuring the 32³-cell topology");
    let unit = Point3::new(1.0, 1.0, 1.0);
    let (coarse, _) = timed(|| box_grid(Point3::origin(), unit, [4, 4, 4]));
    let (h, refined_s) = timed(|| LatticeHierarchy::new(&coarse?, 3));
    let h = h?;
    let level3_cells = h.level(3).topology.num_cells();
    let refined_bytes = h.topology_bytes(3);
    // The same level as the FFD builds it: type-n cells and boundary quads.
    let ((compact, boundary), compact_s) = {
        let (r, s) = timed(|| refined_cells(&h.level(2).topology));
        (r?, s)
    };
    let compact_bytes = compact.bytes() + 16 * boundary.len();
    let (grid, grid_s) = timed(|| box_grid(Point3::origin(), unit, [32, 32, 32]));
    let grid = grid?;
    let grid_bytes = grid.topology.bytes() + grid.tags.corners.len() + grid.tags.sharp_edges.len();
    let b_bytes = 12 * ffd.b.num_entries() + 4 * (ffd.b.num_rows() + 1);
    drop(progress);

    let threads = rayon::current_num_threads();
    let r = &ffd.report;
    let mb = |b: usize| b as Real / (1024.0 * 1024.0);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "subdyn bench ffd: {n}×{m} torus ({} vertices); lattice: AABB, {} octree level{} → {} cells, {} control points; refined {} times → {} cells; {threads} threads{}",
        thousands(points.len()),
        args.octree_levels,
        if args.octree_levels == 1 { "" } else { "s" },
        lattice.topology.num_cells(),
        thousands(lattice.num_vertices()),
        args.levels,
        thousands(r.level_cells),
        if args.repeat > 1 {
            format!("; best of {}", args.repeat)
        } else {
            String::new()
        }
    );
    let _ = writeln!(text, "\n{:<52}{:>12}", "", "seconds");
    let _ = writeln!(text, "{:<52}{lattice_s:>12.4}", "build the octree lattice");
    let _ = writeln!(
        text,
        "{:<52}{refine_s:>12.4}",
        "refine (topology, S_n, level-n points)"
    );
    let _ = writeln!(
        text,
        "{:<52}{embed_s:>12.4}",
        "embed the vertices, form B = W S_n and Bᵀ"
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.4}   (goal < 0.3 s)",
        "embedding total",
        refine_s + embed_s
    );
    let _ = writeln!(
        text,
        "\n{:<52}{:>12}",
        format!(
            "move control point {moved} ({} vertices in its column)",
            thousands(column)
        ),
        "ms / update"
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.4}   (goal < 2 ms)",
        format!("local update (column of B), mean of {}", args.updates),
        1e3 * local_s
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.4}",
        format!("full product B p, mean of {full_runs}"),
        1e3 * full_s
    );
    let _ = writeln!(
        text,
        "local update is {:.0}× faster than the full product; max |local − full| = {max_diff:.1e}",
        full_s / local_s
    );
    let _ = writeln!(text, "\n{:<52}{:>12}", "memory", "MB");
    let _ = writeln!(
        text,
        "{:<52}{:>12.2}   (paper: 20 MB)",
        format!(
            "full incidences: 4³ box refined 3 times ({} cells)",
            thousands(level3_cells)
        ),
        mb(refined_bytes)
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.2}   (goal < 5 MB)",
        "  same level as the FFD keeps it: type-n cells + boundary quads",
        mb(compact_bytes)
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.2}",
        format!(
            "topology: 32³ box grid ({} cells)",
            thousands(grid.topology.num_cells())
        ),
        mb(grid_bytes)
    );
    let _ = writeln!(
        text,
        "{:<52}{:>12.2}",
        format!("B ({} weights)", thousands(ffd.b.num_entries())),
        mb(b_bytes)
    );
    let _ = writeln!(
        text,
        "time to build the 4³ box refined 3 times: {refined_s:.3} s (its last level in compact form: {compact_s:.3} s); the 32³ box grid: {grid_s:.3} s"
    );
    let line = json!({
        "vertices": points.len(),
        "threads": threads,
        "octree_levels": args.octree_levels,
        "lattice_cells": lattice.topology.num_cells(),
        "lattice_control_points": lattice.num_vertices(),
        "levels": args.levels,
        "level_cells": r.level_cells,
        "embedded": r.embedded,
        "outside": r.outside,
        "lattice_s": lattice_s,
        "refine_s": refine_s,
        "embed_s": embed_s,
        "embedding_total_s": refine_s + embed_s,
        "moved_control_point": moved,
        "column_vertices": column,
        "rows_touched": touched,
        "local_update_ms": 1e3 * local_s,
        "full_product_ms": 1e3 * full_s,
        "local_speedup": full_s / local_s,
        "max_abs_diff_local_vs_full": max_diff,
        "refined_32_topology_bytes": refined_bytes,
        "refined_32_cells": level3_cells,
        "refined_32_compact_bytes": compact_bytes,
        "refined_32_compact_build_s": compact_s,
        "refined_32_build_s": refined_s,
        "grid_32_topology_bytes": grid_bytes,
        "grid_32_build_s": grid_s,
        "b_bytes": b_bytes,
    });
    let _ = writeln!(text, "{line}");
    print_stdout(&text)
}

//! `subdyn bench subdivide`: time every stage of uniform refinement of an
//! N×N quad torus and compare with OpenSubdiv 3.6.
//!
//! Stages, timed separately: level-0 topology ([`Refiner::new`]), topology
//! refinement ([`refine_topology`] per level), stencil build ([`refine_stencil`]
//! per level, composed into one table `P_L = S P_0`), stencil application
//! (the composed table, best of `--repeat`), and level-by-level application.

use std::fmt::Write as _;

use clap::{Args, Subcommand};
use serde_json::json;

use subdyn::math::Point3;
use subdyn::stencil::StencilTable;
use subdyn::subdivision::{RefineOptions, Refiner, refine_stencil, refine_topology};
use subdyn::topology::Level;

use super::common::{print_stdout, thousands, timed};
use super::progress::Progress;
use super::subdivide::MAX_FACES;

/// Benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Uniform Catmull-Clark refinement of an N×N quad torus, stage by stage;
    /// the last stdout line is one JSON object with the seconds.
    Subdivide(BenchSubdivideArgs),
    /// Exact closest points on the limit surface against a tessellation +
    /// k-d tree baseline; the last stdout line is one JSON object.
    Closest(super::bench_closest::BenchClosestArgs),
    /// Exact point-to-triangle-mesh distances (BVH) against brute force;
    /// the last stdout line is one JSON object.
    Distance(super::bench_distance::BenchDistanceArgs),
    /// Recovering a torus from a synthetic N³ volume, stage by stage, with
    /// peak memory; the last stdout line is one JSON object.
    Recover(super::bench_recover::BenchRecoverArgs),
    /// Free-form deformation of a 50k-vertex model with an octree lattice:
    /// embedding, one-point updates, topology memory; the last stdout line
    /// is one JSON object.
    Ffd(super::bench_ffd::BenchFfdArgs),
    /// Fitting a range scan (default: the embedded demo scan), stage by
    /// stage, median of several runs; the last stdout line is one JSON object.
    Fit(super::bench_fit::BenchFitArgs),
    /// Time steps of dynamic subdivision solids on the models of McDonnell &
    /// Qin's Table 1, explicit and implicit; one JSON object per row.
    Sculpt(super::bench_sculpt::BenchSculptArgs),
}

/// Arguments of `subdyn bench subdivide`.
#[derive(Debug, Args)]
pub struct BenchSubdivideArgs {
    /// The torus has N×N quads.
    #[arg(long, value_name = "N", default_value_t = 316)]
    pub grid: usize,
    /// Refinement levels (1 to 8).
    #[arg(long, value_name = "L", default_value_t = 2)]
    pub levels: usize,
    /// Stencil applications timed; the best is reported.
    #[arg(long, value_name = "R", default_value_t = 5)]
    pub repeat: usize,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs a benchmark.
pub fn run(cmd: &BenchCommand) -> anyhow::Result<()> {
    match cmd {
        BenchCommand::Subdivide(args) => bench_subdivide(args),
        BenchCommand::Closest(args) => super::bench_closest::bench_closest(args),
        BenchCommand::Distance(args) => super::bench_distance::bench_distance(args),
        BenchCommand::Recover(args) => super::bench_recover::bench_recover(args),
        BenchCommand::Ffd(args) => super::bench_ffd::bench_ffd(args),
        BenchCommand::Sculpt(args) => super::bench_sculpt::bench_sculpt(args),
        BenchCommand::Fit(args) => super::bench_fit::bench_fit(args),
    }
}

/// Seconds of each stage and the sizes involved.
struct Timings {
    topology_s: f64,
    refine_s: f64,
    stencil_build_s: f64,
    stencil_apply_s: f64,
    apply_levelwise_s: f64,
    vertices: usize,
    faces: usize,
    stencil_entries: usize,
    max_abs_diff: f64,
}

fn bench_subdivide(args: &BenchSubdivideArgs) -> anyhow::Result<()> {
    if args.grid < 3 {
        anyhow::bail!(
            "--grid {} is too small: a quad torus needs N ≥ 3",
            args.grid
        );
    }
    if args.levels == 0 || args.levels > 8 {
        anyhow::bail!("--levels {} is out of range: expected 1 to 8", args.levels);
    }
    // In floating point: N × N overflows for a huge --grid.
    let faces = (args.grid as f64).powi(2) * 4f64.powi(args.levels as i32);
    if faces > MAX_FACES as f64 {
        anyhow::bail!(
            "--grid {} --levels {} would make about {} faces (at most {} allowed)",
            args.grid,
            args.levels,
            thousands(faces as usize),
            thousands(MAX_FACES)
        );
    }
    subdyn::subdivision::check_refinement_memory(
        faces,
        false,
        &format!("--grid {} --levels {}", args.grid, args.levels),
    )?;
    if args.repeat == 0 {
        anyhow::bail!("--repeat must be at least 1");
    }
    let progress = Progress::new(args.quiet);
    let t = measure(args, &progress)?;
    drop(progress);

    let threads = rayon::current_num_threads();
    let ours = [
        t.topology_s,
        t.refine_s,
        t.stencil_build_s,
        t.stencil_apply_s,
    ];
    let setup = t.topology_s + t.refine_s + t.stencil_build_s;

    let mut text = String::new();
    let n = args.grid;
    let _ = writeln!(
        text,
        "subdyn bench subdivide: {n}×{n} quad torus ({} faces), {} level{} -> {} vertices, {} faces",
        thousands(n * n),
        args.levels,
        if args.levels == 1 { "" } else { "s" },
        thousands(t.vertices),
        thousands(t.faces)
    );
    let _ = writeln!(
        text,
        "composed stencil table: {} rows, {} entries; f64; {threads} threads; apply = best of {}",
        thousands(t.vertices),
        thousands(t.stencil_entries),
        args.repeat
    );
    let _ = writeln!(text);
    let _ = writeln!(text, "{:<28}{:>12}", "stage", "subdyn (s)");
    let names = ["topology", "refinement", "stencil build", "stencil apply"];
    for (name, ours) in names.iter().zip(ours) {
        let _ = writeln!(text, "{name:<28}{ours:>12.4}");
    }
    let _ = writeln!(text, "{:<28}{setup:>12.4}", "setup (sum of first three)");
    let _ = writeln!(
        text,
        "{:<28}{:>12.4}",
        "apply level by level", t.apply_levelwise_s
    );
    let _ = writeln!(
        text,
        "(OpenSubdiv's Far on the same torus is measured beside this in benches/compare/RESULTS.md; \
         no figure of another run is quoted here)"
    );
    let _ = writeln!(
        text,
        "composed vs level-by-level positions: max |difference| = {:.3e}",
        t.max_abs_diff
    );
    let line = json!({
        "topology_s": t.topology_s,
        "refine_s": t.refine_s,
        "stencil_build_s": t.stencil_build_s,
        "stencil_apply_s": t.stencil_apply_s,
        "apply_levelwise_s": t.apply_levelwise_s,
        "setup_s": setup,
        "grid": n,
        "levels": args.levels,
        "vertices": t.vertices,
        "faces": t.faces,
        "stencil_entries": t.stencil_entries,
        "repeat": args.repeat,
        "threads": threads,
        "precision": "f64",
        "max_abs_diff": t.max_abs_diff,
    });
    let _ = writeln!(text, "{line}");
    print_stdout(&text)
}

fn measure(args: &BenchSubdivideArgs, progress: &Progress) -> anyhow::Result<Timings> {
    let mesh = subdyn::examples::torus(args.grid, args.grid, 1.0, 0.3);
    let p0 = &mesh.positions;

    progress.stage("level-0 topology");
    let (refiner, topology_s) = timed(|| Refiner::new(&mesh, &RefineOptions::default()));
    let refiner = refiner?;

    progress.stage("refining the topology");
    let (children, refine_s) = timed(|| {
        let mut children: Vec<Level> = Vec::with_capacity(args.levels);
        for _ in 0..args.levels {
            let child = refine_topology(children.last().unwrap_or(&refiner.level));
            children.push(child);
        }
        children
    });

    progress.stage("building the stencil tables");
    let sharp0 = refiner.sharpness.clone();
    let (built, stencil_build_s) = timed(|| -> anyhow::Result<_> {
        let mut tables: Vec<StencilTable> = Vec::with_capacity(args.levels);
        let mut sharp = sharp0;
        for (k, child) in children.iter().enumerate() {
            let parent = if k == 0 {
                &refiner.level
            } else {
                &children[k - 1]
            };
            let (table, next) = refine_stencil(parent, &sharp, child, false);
            tables.push(table);
            sharp = next;
        }
        let mut composed: Option<StencilTable> = None;
        for table in &tables[1..] {
            let inner = composed.as_ref().unwrap_or(&tables[0]);
            composed = Some(table.compose(inner)?);
        }
        Ok((tables, composed))
    });
    let (tables, composed) = built?;
    let composed = composed.as_ref().unwrap_or(&tables[0]);

    progress.stage("applying the composed stencil table");
    let mut out = vec![Point3::origin(); composed.num_rows()];
    let stencil_apply_s = best_of(args.repeat, || composed.apply_into(p0, &mut out));

    progress.stage("applying the stencil tables level by level");
    let mut buffers: Vec<Vec<Point3>> = tables
        .iter()
        .map(|t| vec![Point3::origin(); t.num_rows()])
        .collect();
    let apply_levelwise_s = best_of(args.repeat, || {
        for (k, table) in tables.iter().enumerate() {
            let (done, rest) = buffers.split_at_mut(k);
            let input = done.last().map_or(p0.as_slice(), Vec::as_slice);
            table.apply_into(input, &mut rest[0]);
        }
    });
    let finest = buffers.last().map_or(p0.as_slice(), Vec::as_slice);
    let max_abs_diff = out
        .iter()
        .zip(finest)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);

    let finest_level = children.last().unwrap_or(&refiner.level);
    Ok(Timings {
        topology_s,
        refine_s,
        stencil_build_s,
        stencil_apply_s,
        apply_levelwise_s,
        vertices: finest_level.num_vertices,
        faces: finest_level.num_faces(),
        stencil_entries: composed.num_entries(),
        max_abs_diff,
    })
}

/// The shortest of `repeat` runs of `f`, in seconds.
fn best_of(repeat: usize, mut f: impl FnMut()) -> f64 {
    (0..repeat)
        .map(|_| timed(&mut f).1)
        .fold(f64::INFINITY, f64::min)
}

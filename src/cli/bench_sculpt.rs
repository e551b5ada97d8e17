//! `subdyn bench sculpt`: time steps of dynamic subdivision solids on the
//! models of McDonnell & Qin's Table 1 (Pentium III 550 MHz, explicit
//! integration) with the explicit and the implicit integrator.
//!
//! Lattices, rebuilt to the paper's element counts:
//! - cube 3³: a 2×2×2 box grid (27 points, 54 edges, 36 faces, 8 cells);
//! - cube 4³: a 3×3×3 box grid (64, 144, 108, 27);
//! - torus: a square ring of four hexahedra joined by four corner wedges
//!   (triangular prisms), one cell thick (24, 52, 36, 8);
//! - cylinder: four wedges around the axis, two layers (15, 34, 28, 8).
//!
//! Every row starts from the same deformed state (a shear and a bulge of
//! the control points with a velocity field) with default material, so the
//! springs and the CG solves do real work. Each row prints one JSON object
//! `{"model", "level", "mass_points", "paper_ms", "explicit_ms",
//! "implicit_ms", …}` on its own line; `mass_points` is ours, and
//! `paper_mass_points` the paper's. `explicit_ms` and `implicit_ms` are
//! median step times (`…_mean_ms` the means); `implicit_cg_iterations` the
//! mean CG iterations per implicit step and `implicit_refreshes` how many of
//! the timed steps rebuilt the lagged Hessian preconditioner (its cost is in
//! the mean). `implicit_laplacian_ms` (and `…_mean_ms`, `…_cg_iterations`)
//! time the implicit step from the same state with the spring-Laplacian
//! preconditioner, the one used before the lagged Hessian.

use std::fmt::Write as _;

use clap::Args;
use serde_json::json;

use subdyn::lattice::{Lattice, box_grid, extrude};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::solid::{ImplicitPreconditioner, Solid, SolidParams};

use super::common::{print_stdout, thousands, timed};
use super::progress::Progress;

/// Arguments of `subdyn bench sculpt`.
#[derive(Debug, Args)]
pub struct BenchSculptArgs {
    /// Steps timed per row and integrator; the median step is reported (and the mean).
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub steps: usize,
    /// Explicit time step; the implicit step is ten times larger.
    #[arg(long, value_name = "DT", default_value_t = 2e-3)]
    pub dt: f64,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// One row of Table 1: name, level, paper's data points, paper's ms.
struct Row {
    model: &'static str,
    level: usize,
    paper_points: usize,
    paper_ms: Real,
}

const ROWS: [Row; 7] = [
    Row {
        model: "cube 3^3",
        level: 2,
        paper_points: 729,
        paper_ms: 30.0,
    },
    Row {
        model: "cube 3^3",
        level: 3,
        paper_points: 4913,
        paper_ms: 189.0,
    },
    Row {
        model: "cube 4^3",
        level: 1,
        paper_points: 343,
        paper_ms: 20.0,
    },
    Row {
        model: "cube 4^3",
        level: 2,
        paper_points: 2197,
        paper_ms: 121.0,
    },
    Row {
        model: "torus",
        level: 2,
        paper_points: 680,
        paper_ms: 28.0,
    },
    Row {
        model: "torus",
        level: 3,
        paper_points: 4464,
        paper_ms: 163.0,
    },
    Row {
        model: "cylinder",
        level: 3,
        paper_points: 3553,
        paper_ms: 110.0,
    },
];

/// The control lattice of a Table 1 model.
pub fn table1_lattice(model: &str) -> anyhow::Result<Lattice> {
    let unit = Point3::new(1.0, 1.0, 1.0);
    Ok(match model {
        "cube 3^3" => box_grid(Point3::origin(), unit, [2, 2, 2])?,
        "cube 4^3" => box_grid(Point3::origin(), unit, [3, 3, 3])?,
        "torus" => {
            // Inner square corners I_k, and two outer points per corner.
            let mut pos = Vec::new();
            let corners = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)];
            for &(x, y) in &corners {
                pos.push(Point3::new(x, y, 0.0));
            }
            for &(x, y) in &corners {
                pos.push(Point3::new(2.0 * x, y, 0.0));
                pos.push(Point3::new(x, 2.0 * y, 0.0));
            }
            // Outer points of corner k: 4 + 2k (along x) and 5 + 2k (along y).
            let mut faces: Vec<Vec<u32>> = Vec::new();
            for k in 0..4u32 {
                faces.push(vec![k, 4 + 2 * k, 5 + 2 * k]);
            }
            // Sides: corner k to k + 1 (0→1 along the top edge y = const, …).
            faces.push(vec![0, 5, 7, 1]);
            faces.push(vec![1, 6, 8, 2]);
            faces.push(vec![2, 9, 11, 3]);
            faces.push(vec![3, 10, 4, 0]);
            let ring = PolyMesh::from_faces(pos, &faces)?;
            extrude(&ring, Vector3::new(0.0, 0.0, 1.0), 1)?
        }
        "cylinder" => {
            let mut pos = vec![Point3::origin()];
            for s in 0..4 {
                let a = std::f64::consts::FRAC_PI_2 * Real::from(s);
                pos.push(Point3::new(a.cos(), a.sin(), 0.0));
            }
            let faces: Vec<Vec<u32>> = (0..4u32).map(|s| vec![0, 1 + s, 1 + (s + 1) % 4]).collect();
            extrude(
                &PolyMesh::from_faces(pos, &faces)?,
                Vector3::new(0.0, 0.0, 1.0),
                2,
            )?
        }
        _ => anyhow::bail!("unknown model {model}"),
    })
}

/// A deformed, moving state: shear, bulge and a rotation-like velocity field.
fn perturb(solid: &mut Solid) -> anyhow::Result<()> {
    let p: Vec<Point3> = solid
        .control_points()
        .iter()
        .map(|q| {
            Point3::new(
                q.x + 0.1 * q.z * q.y,
                q.y - 0.05 * q.x,
                q.z + 0.1 * q.x * q.y,
            )
        })
        .collect();
    let v: Vec<Vector3> = solid
        .control_points()
        .iter()
        .map(|q| Vector3::new(q.y, 0.3 * q.z, -q.x) * 0.1)
        .collect();
    solid.set_state(&p, &v)?;
    Ok(())
}

/// Median and mean step times over some steps.
struct Timing {
    /// Median milliseconds per step (resists the other jobs of a shared machine).
    median: Real,
    /// Mean milliseconds per step.
    mean: Real,
    /// Mean CG iterations per step.
    iterations: Real,
    /// Steps that rebuilt the implicit preconditioner.
    refreshes: usize,
}

/// Times `steps` steps of one integrator.
fn time_steps(solid: &mut Solid, implicit: bool, dt: Real, steps: usize) -> anyhow::Result<Timing> {
    let mut ms = Vec::with_capacity(steps);
    let mut iterations = 0usize;
    let mut refreshes = 0usize;
    for _ in 0..steps {
        let r = if implicit {
            solid.step_implicit(dt)?
        } else {
            solid.step_explicit(dt)?
        };
        ms.push(1e3 * r.seconds);
        iterations += r.iterations;
        refreshes += usize::from(r.refreshed);
    }
    let mean = ms.iter().sum::<Real>() / steps as Real;
    ms.sort_by(Real::total_cmp);
    Ok(Timing {
        median: ms[steps / 2],
        mean,
        iterations: iterations as Real / steps as Real,
        refreshes,
    })
}

/// Runs the benchmark: a table, then one JSON object per row.
pub fn bench_sculpt(args: &BenchSculptArgs) -> anyhow::Result<()> {
    if args.steps == 0 || args.steps > 100_000 {
        anyhow::bail!(
            "--steps {} is out of range: expected 1 to 100,000",
            args.steps
        );
    }
    if !(args.dt.is_finite() && args.dt > 0.0 && args.dt <= 1.0) {
        anyhow::bail!("--dt {} is out of range: expected 0 < DT ≤ 1", args.dt);
    }
    let progress = Progress::new(args.quiet);
    let mut table = String::new();
    let mut lines = String::new();
    let _ = writeln!(
        table,
        "subdyn bench sculpt: {} threads, {} steps per integrator, dt {} s explicit / {} s implicit",
        rayon::current_num_threads(),
        args.steps,
        args.dt,
        10.0 * args.dt
    );
    let _ = writeln!(
        table,
        "{:<10} {:>5} {:>7} {:>7} {:>9} {:>11} {:>11} {:>8} {:>9} {:>12} {:>8} {:>9} {:>8}",
        "model",
        "level",
        "points",
        "paper",
        "paper ms",
        "explicit ms",
        "implicit ms",
        "CG its",
        "refreshes",
        "laplacian ms",
        "CG its",
        "build ms",
        "speedup"
    );
    for row in &ROWS {
        progress.stage(format!("{} level {}", row.model, row.level));
        let lattice = table1_lattice(row.model)?;
        let params = SolidParams {
            level: row.level,
            ..SolidParams::default()
        };
        let (solid, build_s) = timed(|| Solid::new(&lattice, params.clone()));
        let mut solid = solid?;
        let points = solid.mass_points().len();
        perturb(&mut solid)?;
        let explicit = time_steps(&mut solid.clone(), false, args.dt, args.steps)?;
        // Both preconditioners from the same state: three explicit steps,
        // one untimed implicit step (the first factorisation), then `steps`.
        let mut implicit = Vec::new();
        for preconditioner in [
            ImplicitPreconditioner::Laplacian,
            ImplicitPreconditioner::LaggedHessian,
        ] {
            let mut warm = Solid::new(
                &lattice,
                SolidParams {
                    preconditioner,
                    ..params.clone()
                },
            )?;
            perturb(&mut warm)?;
            time_steps(&mut warm, false, args.dt, 3)?;
            time_steps(&mut warm, true, 10.0 * args.dt, 1)?;
            implicit.push(time_steps(&mut warm, true, 10.0 * args.dt, args.steps)?);
        }
        let (old, new) = (&implicit[0], &implicit[1]);
        let speedup = row.paper_ms / explicit.median;
        let _ = writeln!(
            table,
            "{:<10} {:>5} {:>7} {:>7} {:>9.0} {:>11.3} {:>11.3} {:>8.1} {:>9} {:>12.3} {:>8.1} {:>9.1} {:>7.0}x{}",
            row.model,
            row.level,
            thousands(points),
            thousands(row.paper_points),
            row.paper_ms,
            explicit.median,
            new.median,
            new.iterations,
            new.refreshes,
            old.median,
            old.iterations,
            1e3 * build_s,
            speedup,
            if points == row.paper_points {
                ""
            } else {
                "  (point count differs from the paper)"
            }
        );
        let _ = writeln!(
            lines,
            "{}",
            json!({
                "model": row.model,
                "level": row.level,
                "mass_points": points,
                "paper_ms": row.paper_ms,
                "explicit_ms": explicit.median,
                "implicit_ms": new.median,
                "paper_mass_points": row.paper_points,
                "explicit_mean_ms": explicit.mean,
                "implicit_mean_ms": new.mean,
                "implicit_cg_iterations": new.iterations,
                "implicit_refreshes": new.refreshes,
                "implicit_laplacian_ms": old.median,
                "implicit_laplacian_mean_ms": old.mean,
                "implicit_laplacian_cg_iterations": old.iterations,
                "build_ms": 1e3 * build_s,
                "explicit_speedup": speedup,
            })
        );
    }
    drop(progress);
    print_stdout(&(table + &lines))
}

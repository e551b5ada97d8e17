//! `subdyn sculpt LAT.json --level L --script OPS.json --out-dir DIR
//! [--every K] [--integrator explicit|implicit]`: a scripted sculpting
//! session with a dynamic subdivision solid (McDonnell & Qin); `subdyn sculpt
//! --demo --out-dir DIR` runs the built-in session (figs. 7–10 in spirit).
//!
//! Writes `DIR/frame_SSSSSSS.obj` (the level-`L` lattice's boundary surface)
//! at step 0, every `K` steps and at the last step, and `DIR/log.json` (energy
//! and timing per frame, what every operation did). The demo also writes
//! `DIR/sculpt_demo.png`, a strip of key frames. Every file is written
//! atomically.
//!
//! # Script format
//!
//! Plain JSON, documented with a runnable example in `docs/sculpt.md`
//! (`{"dt": 0.002, "steps": 900, "material": {…}, "ops": [{"step": 0, "op":
//! "rope", …}, …]}`); parsed and checked up front, before the first step, by
//! [`super::sculpt_script`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use serde_json::{Value, json};

use subdyn::io::{read_lattice, write_mesh};
use subdyn::lattice::Lattice;
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;
use subdyn::solid::{MAX_SOLID_LEVEL, Solid, Stiffness};

use super::common::{Written, about_file, seconds, write_report};
use super::progress::Progress;
use super::sculpt_script::{
    MAX_STEPS, Op, Script, check_script, extruded_face, parse_script, read_script, selection,
    solid_params, trimmed_cell,
};

/// Which integrator steps the solid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Integrator {
    /// The paper's explicit scheme (symplectic Euler on eq. 6).
    #[default]
    Explicit,
    /// Backward Euler with CG on the control-point system.
    Implicit,
}

/// Arguments of `subdyn sculpt`.
#[derive(Debug, Args)]
pub struct SculptArgs {
    /// The control lattice (lattice JSON).
    #[arg(
        value_name = "LAT.json",
        required_unless_present = "demo",
        conflicts_with = "demo"
    )]
    pub lattice: Option<PathBuf>,
    /// Refinement level of the mass-point lattice (0 to 4).
    #[arg(long, value_name = "L", default_value_t = 2)]
    pub level: usize,
    /// The session script (plain JSON; format and example in docs/sculpt.md).
    #[arg(
        long,
        value_name = "OPS.json",
        required_unless_present = "demo",
        conflicts_with = "demo"
    )]
    pub script: Option<PathBuf>,
    /// Directory for the frames, the log (and the demo's picture); created if missing.
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Write a frame every K steps.
    #[arg(long, value_name = "K", default_value_t = 10)]
    pub every: usize,
    /// Time integrator.
    #[arg(long, value_enum, default_value_t = Integrator::Explicit)]
    pub integrator: Integrator,
    /// Run the built-in session on a 3×3×3-point cube instead of a script.
    #[arg(long)]
    pub demo: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// A boundary surface and control-lattice hull kept for a picture.
pub struct Snapshot {
    /// The step.
    pub step: usize,
    /// The solid's boundary surface.
    pub surface: PolyMesh,
    /// The control lattice's hull.
    pub lattice: PolyMesh,
    /// Fixed control points.
    pub fixed: Vec<Point3>,
}

/// A rope whose far end moves linearly from `from` (at `start`) to `to` (at `until`).
struct MovingRope {
    rope: usize,
    from: Point3,
    to: Point3,
    start: usize,
    until: usize,
}

/// Runs the verb.
pub fn run(args: &SculptArgs) -> anyhow::Result<()> {
    subdyn::io::check_output_dir_path(&args.out_dir)?;
    if args.every == 0 || args.every > MAX_STEPS {
        anyhow::bail!(
            "--every {} is out of range: expected 1 to {MAX_STEPS}",
            args.every
        );
    }
    if args.level > MAX_SOLID_LEVEL {
        anyhow::bail!(
            "--level {} is out of range: expected 0 to {MAX_SOLID_LEVEL}",
            args.level
        );
    }
    let (lattice, script, name) = if args.demo {
        let what = "the demo script";
        let script = parse_script(super::sculpt_demo::DEMO_SCRIPT, what)?;
        let lattice = super::sculpt_demo::demo_lattice()?;
        check_script(&script, &lattice, args.level, what)?;
        (lattice, script, "demo cube".to_string())
    } else {
        let (Some(lat), Some(path)) = (&args.lattice, &args.script) else {
            anyhow::bail!("give a lattice and --script, or --demo");
        };
        let lattice = read_lattice(lat).map_err(|e| about_file(e, lat))?;
        let script = read_script(path)?;
        check_script(&script, &lattice, args.level, &path.display().to_string())?;
        (lattice, script, lat.display().to_string())
    };
    subdyn::io::create_output_dir(&args.out_dir)?;
    let progress = Progress::new(args.quiet);
    progress.stage(format!("building the level-{} solid", args.level));
    let params = solid_params(args.level, &script.material);
    let mut solid =
        Solid::new(&lattice, params).with_context(|| format!("{name}: cannot build the solid"))?;
    let snapshot_steps: Vec<usize> = if args.demo {
        super::sculpt_demo::DEMO_SNAPSHOTS
            .iter()
            .map(|s| s.0)
            .collect()
    } else {
        Vec::new()
    };
    let start = Instant::now();
    let mass_points = solid.mass_points().len();
    let (frames, ops, snapshots, step_ms) =
        session(&mut solid, &script, args, &snapshot_steps, &progress)?;
    drop(progress);
    let mean_ms = step_ms.iter().sum::<Real>() / step_ms.len().max(1) as Real;
    let log = json!({
        "lattice": name,
        "level": args.level,
        "integrator": format!("{:?}", args.integrator).to_lowercase(),
        "dt": script.dt,
        "steps": script.steps,
        "every": args.every,
        "mass_points_start": mass_points,
        "mass_points_end": solid.mass_points().len(),
        "mean_step_ms": mean_ms,
        "max_step_ms": step_ms.iter().copied().fold(0.0, Real::max),
        "total_s": seconds(start),
        "ops": ops,
        "frames": frames,
    });
    let mut written = Written::new();
    for frame in &frames {
        if let Some(step) = frame["step"].as_u64() {
            let path = frame_path(&args.out_dir, step as usize);
            written.add(&path, format!("frame, step {step}"));
        }
    }
    let log_path = args.out_dir.join("log.json");
    write_report(&log_path, &log)?;
    written.add(&log_path, "log");
    let text = format!(
        "subdyn sculpt: {name}, level {}, {} steps of {} s ({:?}), {} → {} mass points, {:.3} ms per step; {} frames\n",
        args.level,
        script.steps,
        script.dt,
        args.integrator,
        mass_points,
        solid.mass_points().len(),
        mean_ms,
        frames.len(),
    );
    if args.demo {
        let path = args.out_dir.join("sculpt_demo.png");
        super::sculpt_demo::write_strip(&snapshots, &path)?;
        written.add(&path, "key frames picture");
    }
    written.print_after(&text)
}

type SessionOutput = (Vec<Value>, Vec<Value>, Vec<Snapshot>, Vec<Real>);

/// Runs the script: ops, rope targets, frames, steps.
fn session(
    solid: &mut Solid,
    script: &Script,
    args: &SculptArgs,
    snapshot_steps: &[usize],
    progress: &Progress,
) -> anyhow::Result<SessionOutput> {
    let mut frames = Vec::new();
    let mut op_log = Vec::new();
    let mut snapshots = Vec::new();
    let mut step_ms = Vec::with_capacity(script.steps);
    let mut moving: Vec<MovingRope> = Vec::new();
    let mut next_op = 0;
    let mut since_frame = (0.0, 0usize, 0usize); // (ms, steps, max CG iterations)
    for step in 0..=script.steps {
        while next_op < script.ops.len() && script.ops[next_op].step == step {
            let op = &script.ops[next_op];
            let t0 = Instant::now();
            let detail = apply(solid, &op.op, step, &mut moving)
                .with_context(|| format!("script {}", op.label()))?;
            op_log.push(
                json!({"step": step, "op": op.op.name(), "detail": detail, "ms": 1e3 * seconds(t0)}),
            );
            next_op += 1;
        }
        for m in &moving {
            let t = if m.until <= m.start {
                1.0
            } else {
                ((step - m.start.min(step)) as Real / (m.until - m.start) as Real).min(1.0)
            };
            solid.set_rope_target(m.rope, m.from + (m.to - m.from) * t)?;
        }
        if step % args.every == 0 || step == script.steps {
            let path = frame_path(&args.out_dir, step);
            write_mesh(&path, &solid.boundary_mesh()?, None)?;
            let (ms, n, it) = since_frame;
            frames.push(json!({
                "step": step,
                "time": solid.time(),
                "kinetic": solid.kinetic_energy(),
                "spring": solid.spring_energy(),
                "rope": solid.rope_energy(),
                "mass_points": solid.mass_points().len(),
                "mean_step_ms": if n > 0 { ms / n as Real } else { 0.0 },
                "max_cg_iterations": it,
            }));
            since_frame = (0.0, 0, 0);
        }
        progress.counted(step as u64, script.steps as u64, "steps");
        if snapshot_steps.contains(&step) {
            snapshots.push(snapshot(solid, step)?);
        }
        if step == script.steps {
            break;
        }
        let report = match args.integrator {
            Integrator::Explicit => solid.step_explicit(script.dt),
            Integrator::Implicit => solid.step_implicit(script.dt),
        }
        .with_context(|| {
            format!(
                "step {step} (t = {:.4} s) with the {:?} integrator; try a smaller dt or --integrator implicit",
                solid.time(),
                args.integrator
            )
        })?;
        step_ms.push(1e3 * report.seconds);
        since_frame.0 += 1e3 * report.seconds;
        since_frame.1 += 1;
        since_frame.2 = since_frame.2.max(report.iterations);
    }
    if solid
        .mass_points()
        .iter()
        .any(|p| !p.coords.iter().all(|x| x.is_finite()))
    {
        anyhow::bail!(
            "the simulation became unstable (non-finite positions); try a smaller dt or --integrator implicit"
        );
    }
    Ok((frames, op_log, snapshots, step_ms))
}

fn snapshot(solid: &Solid, step: usize) -> anyhow::Result<Snapshot> {
    let lat: Lattice = solid.control_lattice();
    let fixed = solid
        .fixed()
        .iter()
        .zip(solid.control_points())
        .filter(|(f, _)| **f)
        .map(|(_, p)| *p)
        .collect();
    Ok(Snapshot {
        step,
        surface: solid.boundary_mesh()?,
        lattice: lat.boundary_mesh()?,
        fixed,
    })
}

/// Applies one operation; returns a line saying what it did.
fn apply(
    solid: &mut Solid,
    op: &Op,
    step: usize,
    moving: &mut Vec<MovingRope>,
) -> anyhow::Result<String> {
    Ok(match op {
        Op::Rope {
            at,
            to,
            until,
            stiffness,
            rest_length,
        } => {
            let point = solid.nearest_mass_point(&Point3::new(at[0], at[1], at[2]));
            let from = solid.mass_points()[point];
            let rope = solid.add_rope(
                point,
                from,
                stiffness.unwrap_or(50.0),
                rest_length.unwrap_or(0.0),
            )?;
            moving.push(MovingRope {
                rope,
                from,
                to: Point3::new(to[0], to[1], to[2]),
                start: step,
                until: until.unwrap_or(step),
            });
            format!("rope on mass point {point}")
        }
        Op::Release => {
            let n = solid.ropes().len();
            solid.release_ropes();
            moving.clear();
            format!("released {n} ropes")
        }
        Op::Extrude { face, near } => {
            let f = extruded_face(&solid.control_lattice(), *face, near)?;
            solid.extrude(f)?;
            format!(
                "extruded face {f}; {} cells",
                solid.control_lattice().topology.num_cells()
            )
        }
        Op::Trim { cell, near } => {
            let c = trimmed_cell(&solid.control_lattice(), *cell, near)?;
            solid.trim(c)?;
            format!(
                "trimmed cell {c}; {} cells",
                solid.control_lattice().topology.num_cells()
            )
        }
        Op::Fix { points, bbox } | Op::Free { points, bbox } => {
            let sel = selection(solid, points, bbox);
            if sel.is_empty() {
                anyhow::bail!("the selection holds no control point");
            }
            let fix = matches!(op, Op::Fix { .. });
            solid.set_fixed(&sel, fix)?;
            format!(
                "{} {} control points",
                if fix { "fixed" } else { "freed" },
                sel.len()
            )
        }
        Op::Stiffness { normal, virtual_ } => {
            let k = solid.params().stiffness;
            let k = Stiffness {
                edge: normal.unwrap_or(k.edge),
                virtual_: virtual_.unwrap_or(k.virtual_),
            };
            solid.set_stiffness(k)?;
            format!("stiffness {} / {}", k.edge, k.virtual_)
        }
        Op::Damping { value } => {
            solid.set_damping(*value)?;
            format!("damping {value}")
        }
        Op::Plastic { halt } => {
            solid.make_plastic()?;
            if halt.unwrap_or(true) {
                solid.halt();
            }
            "rest shape reset to the current shape".to_string()
        }
    })
}

/// The output directory's frame path for `step`.
fn frame_path(dir: &Path, step: usize) -> PathBuf {
    dir.join(format!("frame_{step:07}.obj"))
}

//! Dynamic subdivision solids: rest, momentum, energy decay, make plastic,
//! stability of the implicit integrator against the explicit one, fixed
//! points, extrude/trim round trips, the implicit step's preconditioners and
//! bad input.

use subdyn::lattice::{Lattice, box_grid};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::solid::{
    ExplicitScheme, ImplicitPreconditioner, Solid, SolidParams, SpringHessians, SpringNetwork,
    Stiffness, extrude_face, trim_cell,
};

mod common;

fn cube() -> Lattice {
    box_grid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 1.0),
        [2, 2, 2],
    )
    .unwrap()
}

fn solid(level: usize, damping: Real) -> Solid {
    let params = SolidParams {
        level,
        damping,
        ..SolidParams::default()
    };
    Solid::new(&cube(), params).unwrap()
}

/// A deterministic deformation of the cube's control points (a shear and a
/// bulge) with a small velocity field, so that springs are stretched and
/// the solid moves.
fn perturb(s: &mut Solid, amount: Real) {
    let p: Vec<Point3> = s
        .control_points()
        .iter()
        .map(|q| {
            Point3::new(
                q.x + amount * q.z * q.y,
                q.y - amount * 0.5 * q.x,
                q.z + amount * (q.x - 0.5) * (q.y - 0.5),
            )
        })
        .collect();
    let v: Vec<Vector3> = s
        .control_points()
        .iter()
        .map(|q| Vector3::new(q.y - 0.5, 0.3 * q.z, -(q.x - 0.5)) * amount)
        .collect();
    s.set_state(&p, &v).unwrap();
}

fn max_move(a: &[Point3], b: &[Point3]) -> Real {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, Real::max)
}

#[test]
fn without_forces_the_solid_stays_at_rest() {
    let mut s = solid(2, 2.0);
    let d0 = s.mass_points().to_vec();
    assert_eq!(d0.len(), 729);
    assert!(s.spring_energy() < 1e-20);
    for _ in 0..50 {
        s.step_explicit(1e-3).unwrap();
    }
    for _ in 0..10 {
        s.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&d0, s.mass_points()) < 1e-13);
    assert!(s.kinetic_energy() < 1e-24);
}

#[test]
fn momentum_is_conserved_without_damping_and_fixed_points() {
    let params = SolidParams {
        level: 2,
        damping: 0.0,
        cg_tolerance: 1e-10,
        ..SolidParams::default()
    };
    let mut s = Solid::new(&cube(), params).unwrap();
    perturb(&mut s, 0.2);
    let m0 = s.momentum();
    assert!(m0.norm() > 1e-2, "the test needs a moving solid");
    assert!(s.spring_energy() > 1e-2);
    for _ in 0..200 {
        s.step_explicit(2e-3).unwrap();
    }
    assert!(
        (s.momentum() - m0).norm() < 1e-10 * m0.norm(),
        "{:?} vs {m0:?}",
        s.momentum()
    );
    for _ in 0..20 {
        s.step_implicit(1e-2).unwrap();
    }
    // CG stops at a relative residual of 1e-10.
    assert!(
        (s.momentum() - m0).norm() < 1e-6 * m0.norm(),
        "{:?} vs {m0:?}",
        s.momentum()
    );
    // A rope is an external force: momentum changes.
    let far = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(far, Point3::new(3.0, 1.0, 1.0), 50.0, 0.0)
        .unwrap();
    s.step_explicit(2e-3).unwrap();
    assert!((s.momentum() - m0).norm() > 1e-3 * m0.norm());
}

#[test]
fn energy_decays_with_damping() {
    for implicit in [false, true] {
        let mut s = solid(2, 4.0);
        perturb(&mut s, 0.2);
        let e0 = s.energy();
        let mut worst: Real = 0.0;
        for _ in 0..150 {
            if implicit {
                s.step_implicit(1e-2).unwrap();
            } else {
                for _ in 0..5 {
                    s.step_explicit(2e-3).unwrap();
                }
            }
            worst = worst.max(s.energy());
        }
        let e1 = s.energy();
        assert!(
            worst <= e0 * (1.0 + 1e-9),
            "implicit {implicit}: energy rose from {e0} to {worst}"
        );
        assert!(
            e1 < 0.05 * e0,
            "implicit {implicit}: energy {e1} after 1.5 s (start {e0})"
        );
    }
}

#[test]
fn after_make_plastic_the_deformed_shape_is_at_rest() {
    let mut s = solid(2, 2.0);
    let d0 = s.mass_points().to_vec();
    let corner = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(corner, Point3::new(1.6, 1.4, 1.5), 80.0, 0.0)
        .unwrap();
    for _ in 0..100 {
        s.step_implicit(1e-2).unwrap();
    }
    s.release_ropes();
    let deformed = s.mass_points().to_vec();
    assert!(
        max_move(&d0, &deformed) > 0.05,
        "the rope did not deform the cube"
    );
    s.make_plastic().unwrap();
    s.halt();
    assert!(s.spring_energy() < 1e-24);
    for _ in 0..50 {
        s.step_explicit(2e-3).unwrap();
        s.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&deformed, s.mass_points()) < 1e-13);
    // Without make plastic the same deformation springs back.
    let mut t = solid(2, 2.0);
    t.add_rope(corner, Point3::new(1.6, 1.4, 1.5), 80.0, 0.0)
        .unwrap();
    for _ in 0..100 {
        t.step_implicit(1e-2).unwrap();
    }
    t.release_ropes();
    t.halt();
    let before = t.mass_points().to_vec();
    for _ in 0..10 {
        t.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&before, t.mass_points()) > 1e-3);
}

/// Largest spring energy over `steps` explicit steps from a perturbed,
/// undamped cube, relative to the start (infinite when it blew up).
fn explicit_growth(h: Real, steps: usize) -> Real {
    let mut s = solid(2, 0.0);
    perturb(&mut s, 0.05);
    let e0 = s.energy();
    let mut worst: Real = 1.0;
    for _ in 0..steps {
        if s.step_explicit(h).is_err() {
            return Real::INFINITY;
        }
        let e = s.energy();
        if !e.is_finite() {
            return Real::INFINITY;
        }
        worst = worst.max(e / e0);
    }
    worst
}

#[test]
fn implicit_is_stable_at_ten_times_the_largest_stable_explicit_step() {
    // Bisection (in log scale) for the largest explicit step whose energy
    // stays within twice its start over 300 undamped steps.
    let stable = |h: Real| explicit_growth(h, 300) < 2.0;
    let (mut lo, mut hi) = (1e-4, 1.0);
    assert!(stable(lo) && !stable(hi));
    for _ in 0..14 {
        let mid = (lo * hi).sqrt();
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let h_max = lo;
    eprintln!("largest stable explicit step on the level-2 cube: {h_max:.4e} s");
    assert!(hi / lo < 1.01);
    // Both sides: a bit above the threshold the explicit integrator blows up.
    assert!(explicit_growth(1.3 * h_max, 300) > 10.0);
    assert!(explicit_growth(0.7 * h_max, 600) < 1.5);
    // The implicit integrator at 10× (and 100×) that step: energy never grows.
    for factor in [10.0, 100.0] {
        let mut s = solid(2, 0.0);
        perturb(&mut s, 0.05);
        let e0 = s.energy();
        for _ in 0..100 {
            s.step_implicit(factor * h_max).unwrap();
            assert!(
                s.energy() <= e0 * (1.0 + 1e-9),
                "implicit at {factor}×{h_max:.2e} gained energy"
            );
        }
    }
}

#[test]
fn fixed_control_points_do_not_move() {
    let mut s = solid(1, 2.0);
    let left: Vec<usize> = (0..s.control_points().len())
        .filter(|&i| s.control_points()[i].x < 0.1)
        .collect();
    assert_eq!(left.len(), 9);
    s.set_fixed(&left, true).unwrap();
    let p0 = s.control_points().to_vec();
    let corner = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(corner, Point3::new(1.5, 1.5, 1.0), 50.0, 0.0)
        .unwrap();
    for _ in 0..40 {
        s.step_implicit(1e-2).unwrap();
        s.step_explicit(1e-3).unwrap();
    }
    for &i in &left {
        assert_eq!(s.control_points()[i], p0[i]);
    }
    assert!(max_move(&p0, s.control_points()) > 0.05);
    s.set_fixed(&left, false).unwrap();
    s.step_implicit(1e-2).unwrap();
    assert!(left.iter().any(|&i| s.control_points()[i] != p0[i]));
}

#[test]
fn extrude_then_trim_gives_back_the_topology() {
    let lat = cube();
    let top = (0..lat.topology.num_faces())
        .find(|&f| {
            lat.topology.is_boundary_face(f)
                && lat
                    .topology
                    .faces
                    .row(f)
                    .iter()
                    .all(|&v| lat.positions[v as usize].z > 0.99)
        })
        .unwrap();
    let ext = extrude_face(&lat, top).unwrap();
    assert_eq!(ext.topology.num_cells(), 9);
    assert_eq!(ext.num_vertices(), 31);
    // The new cell sits on top, as tall as the cell under it.
    let zmax = ext.positions.iter().map(|p| p.z).fold(0.0, Real::max);
    assert!((zmax - 1.5).abs() < 1e-12);
    let back = trim_cell(&ext, 8).unwrap();
    assert_eq!(back.topology, lat.topology);
    assert_eq!(back.positions, lat.positions);
    assert_eq!(back.tags, lat.tags);

    // The same on a solid: counts change and come back.
    let mut s = solid(1, 2.0);
    let n_mass = s.mass_points().len();
    s.extrude(top).unwrap();
    assert_eq!(s.control_points().len(), 31);
    assert!(s.mass_points().len() > n_mass);
    assert!(s.spring_energy() < 1e-20, "an extruded cell starts at rest");
    s.trim(8).unwrap();
    assert_eq!(s.control_lattice().topology, lat.topology);
    assert_eq!(s.mass_points().len(), n_mass);
    // Trimming a corner cell of the cube keeps a connected lattice.
    s.trim(0).unwrap();
    assert_eq!(s.control_lattice().topology.num_cells(), 7);
    assert_eq!(s.control_points().len(), 26);
}

#[test]
fn bad_input_is_an_error() {
    let mut s = solid(1, 2.0);
    assert!(s.step_explicit(Real::NAN).is_err());
    assert!(s.step_implicit(-1.0).is_err());
    assert!(s.add_rope(1_000_000, Point3::origin(), 1.0, 0.0).is_err());
    assert!(
        s.add_rope(0, Point3::new(Real::NAN, 0.0, 0.0), 1.0, 0.0)
            .is_err()
    );
    assert!(s.set_fixed(&[27], true).is_err());
    assert!(s.set_damping(-1.0).is_err());
    assert!(
        s.set_stiffness(Stiffness {
            edge: Real::INFINITY,
            virtual_: 1.0
        })
        .is_err()
    );
    let interior = (0..36)
        .find(|&f| !s.control_lattice().topology.is_boundary_face(f))
        .unwrap();
    assert!(s.extrude(interior).is_err());
    assert!(s.trim(8).is_err());
    // Failed edits leave the solid as it was.
    assert_eq!(s.control_points().len(), 27);
    assert_eq!(s.mass_points().len(), 125);
    assert_eq!(s.control_lattice().topology, cube().topology);
    let params = SolidParams {
        level: 9,
        ..SolidParams::default()
    };
    assert!(Solid::new(&cube(), params).is_err());
    let one = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut t = Solid::new(&one, SolidParams::default()).unwrap();
    assert!(t.trim(0).is_err());
    // An explicit step far too large blows up and is then reported, not hidden.
    let mut u = solid(1, 0.0);
    perturb(&mut u, 0.1);
    let mut failed = false;
    for _ in 0..2000 {
        if u.step_explicit(1.0).is_err() {
            failed = true;
            break;
        }
    }
    assert!(failed);
}

fn write_cube_json(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("cube.json");
    subdyn::io::write_lattice(&path, &cube()).unwrap();
    path
}

#[test]
fn sculpt_cli_runs_a_script_and_writes_frames_and_a_log() {
    let dir = tempfile::tempdir().unwrap();
    write_cube_json(dir.path());
    let script = r#"{"dt": 0.005, "steps": 40, "ops": [
        {"step": 0, "op": "fix", "box": [[-1, -1, -1], [2, 0.01, 2]]},
        {"step": 0, "op": "rope", "at": [1, 1, 1], "to": [1.3, 1.3, 1.3], "until": 20},
        {"step": 20, "op": "extrude", "near": [0.75, 1, 0.75]},
        {"step": 30, "op": "trim", "cell": 8},
        {"step": 35, "op": "release"},
        {"step": 35, "op": "plastic"}]}"#;
    std::fs::write(dir.path().join("ops.json"), script).unwrap();
    for integrator in ["explicit", "implicit"] {
        let out = common::run_subdyn(
            dir.path(),
            &[
                "sculpt",
                "cube.json",
                "--level",
                "1",
                "--script",
                "ops.json",
                "--out-dir",
                "out",
                "--every",
                "10",
                "--integrator",
                integrator,
            ],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let log: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("out/log.json")).unwrap(),
        )
        .unwrap();
        let frames = log["frames"].as_array().unwrap();
        assert_eq!(frames.len(), 5);
        assert!(
            frames[2]["rope"].as_f64().unwrap() > 0.0 || frames[1]["rope"].as_f64().unwrap() > 0.0
        );
        assert_eq!(
            frames[2]["mass_points"].as_u64(),
            Some(143),
            "extruded at level 1: 125 + 4 vertex, 8 edge, 5 face and 1 cell points"
        );
        assert_eq!(frames[4]["mass_points"].as_u64(), Some(125), "trimmed back");
        assert_eq!(log["ops"].as_array().unwrap().len(), 6);
        let obj = subdyn::io::read_mesh(dir.path().join("out/frame_0000040.obj")).unwrap();
        assert_eq!(obj.num_faces(), 6 * 16);
        // After make plastic and halt the frames stop changing energy.
        assert!(frames[4]["kinetic"].as_f64().unwrap() < 1e-20);
    }
}

#[test]
fn sculpt_cli_rejects_bad_scripts_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    write_cube_json(dir.path());
    let bad = [
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"step": 1, "op": "spin"}]}"#,
            "op 0",
        ),
        (r#"{"dt": -1, "steps": 10}"#, "dt"),
        (r#"{"dt": 0.01, "steps": 0}"#, "steps"),
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"step": 11, "op": "release"}]}"#,
            "after the last step",
        ),
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"op": "release"}]}"#,
            "step",
        ),
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"step": 1, "op": "extrude", "face": 99}]}"#,
            "not a boundary face",
        ),
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"step": 1, "op": "extrude"}]}"#,
            "exactly one",
        ),
        (
            r#"{"dt": 0.01, "steps": 10, "ops": [{"step": 1, "op": "fix", "box": [[5, 5, 5], [6, 6, 6]]}]}"#,
            "no control point",
        ),
        (
            r#"{"dt": 2.0, "steps": 200, "ops": [{"step": 0, "op": "rope", "at": [1, 1, 1], "to": [9, 9, 9], "stiffness": 1000}]}"#,
            "smaller dt",
        ),
        (r#"{"dt": 0.01, "steps": 10"#, "not a valid sculpt script"),
        ("{\"dt\": 0.01, // the step\n \"steps\": 10}", "no comments"),
        // Checked before the first step, however late the op: nothing is written.
        (
            r#"{"dt": 0.01, "steps": 900, "ops": [{"step": 0, "op": "release"}, {"step": 800, "op": "free", "points": [3, 27]}]}"#,
            "op 1 (step 800, free): control point 27 does not exist",
        ),
        (
            r#"{"dt": 0.01, "steps": 900, "ops": [{"step": 700, "op": "trim", "cell": 8}]}"#,
            "op 0 (step 700, trim)",
        ),
        (
            r#"{"dt": 0.01, "steps": 900, "ops": [{"step": 700, "op": "damping", "value": -1}]}"#,
            "op 0 (step 700, damping)",
        ),
        (
            r#"{"dt": 0.01, "steps": 900, "ops": [{"step": 9, "op": "rope", "at": [1, 1, 1], "to": [2, 2, 2], "until": 5}]}"#,
            "op 0 (step 9, rope): until = 5",
        ),
        (
            r#"{"dt": 0.01, "steps": 900, "ops": [{"step": 9, "op": "stiffness"}]}"#,
            "op 0 (step 9, stiffness)",
        ),
        (
            r#"{"dt": 0.01, "steps": 900, "material": {"density": -1}}"#,
            "material",
        ),
    ];
    for (i, (script, expect)) in bad.iter().enumerate() {
        std::fs::write(dir.path().join("bad.json"), script).unwrap();
        let out = common::run_subdyn(
            dir.path(),
            &[
                "sculpt",
                "cube.json",
                "--level",
                "1",
                "--script",
                "bad.json",
                "--out-dir",
                "bad",
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "script {i}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "script {i}: {err}");
        assert!(
            err.contains(expect),
            "script {i}: expected {expect:?} in {err}"
        );
        assert!(
            !dir.path().join("bad").exists(),
            "script {i}: frames written"
        );
    }
    let out = common::run_subdyn(
        dir.path(),
        &[
            "sculpt",
            "cube.json",
            "--level",
            "9",
            "--script",
            "bad.json",
            "--out-dir",
            "bad",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    std::fs::write(
        dir.path().join("broken.json"),
        "{\"vertices\": [[0, 0, 0]], \"hexahedra\": [[0, 0, 0, 0, 0, 0, 0, 0]]}",
    )
    .unwrap();
    std::fs::write(dir.path().join("ok.json"), r#"{"dt": 0.01, "steps": 1}"#).unwrap();
    let out = common::run_subdyn(
        dir.path(),
        &[
            "sculpt",
            "broken.json",
            "--script",
            "ok.json",
            "--out-dir",
            "bad",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("broken.json"), "{err}");
}

/// The script of `docs/sculpt.md` is plain JSON and runs on the lattice the
/// page says to make (extrude, then trim: every op applies).
#[test]
fn the_documented_sculpt_script_runs() {
    let dir = tempfile::tempdir().unwrap();
    let page = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/sculpt.md"),
    )
    .unwrap();
    let script = page
        .split("```json\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("a ```json block in docs/sculpt.md");
    serde_json::from_str::<serde_json::Value>(script).expect("plain JSON");
    std::fs::write(dir.path().join("ops.json"), script).unwrap();
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/opensubdiv/cube.obj"),
        dir.path().join("cube.obj"),
    )
    .unwrap();
    let lattice = common::run_subdyn(
        dir.path(),
        &[
            "lattice",
            "cube.obj",
            "--octree-levels",
            "1",
            "-o",
            "lat.json",
        ],
    );
    assert!(lattice.status.success());
    let out = common::run_subdyn(
        dir.path(),
        &[
            "sculpt",
            "lat.json",
            "--level",
            "1",
            "--script",
            "ops.json",
            "--out-dir",
            "out",
            "--every",
            "300",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/log.json")).unwrap())
            .unwrap();
    let ops = log["ops"].as_array().unwrap();
    assert_eq!(ops.len(), 10);
    assert!(ops.iter().any(|o| o["op"] == "extrude"));
    assert!(ops.iter().any(|o| o["op"] == "trim"));
}

#[test]
fn spring_hessian_is_the_derivative_of_the_spring_forces() {
    // A stretched, sheared level-1 cube: every spring longer than at rest, so
    // no transverse term is clamped and K must equal −∂f/∂x exactly.
    let lat = cube();
    let h = subdyn::lattice::LatticeHierarchy::new(&lat, 1).unwrap();
    let topo = &h.level(1).topology;
    let rest = h
        .stencil_to_level(1)
        .unwrap()
        .apply(&lat.positions)
        .unwrap();
    let net = SpringNetwork::new(topo, &rest).unwrap();
    assert_eq!(net.len(), 300 + 4 * 240);
    let x: Vec<Point3> = rest
        .iter()
        .map(|p| Point3::new(1.2 * p.x + 0.1 * p.y, 1.15 * p.y, 1.25 * p.z + 0.05 * p.x))
        .collect();
    let k = Stiffness {
        edge: 3.0,
        virtual_: 2.0,
    };
    let w: Vec<Vector3> = (0..x.len())
        .map(|i| {
            let t = i as Real;
            Vector3::new((0.7 * t).sin(), (1.3 * t).cos(), (0.4 * t + 1.0).sin())
        })
        .collect();
    let mut hess = SpringHessians::default();
    net.hessians_into(&x, k, &mut hess);
    let mut kw = vec![Vector3::zeros(); x.len()];
    net.add_hessian_product(&hess, &w, &mut kw);
    let eps = 1e-6;
    let force = |sign: Real| {
        let y: Vec<Point3> = x
            .iter()
            .zip(&w)
            .map(|(p, v)| p + v * (sign * eps))
            .collect();
        let mut f = vec![Vector3::zeros(); x.len()];
        net.add_forces(&y, k, &mut f);
        f
    };
    let (fp, fm) = (force(1.0), force(-1.0));
    let scale = kw.iter().map(|v| v.norm()).fold(0.0, Real::max);
    assert!(scale > 1e-2);
    for i in 0..x.len() {
        let fd = -(fp[i] - fm[i]) / (2.0 * eps);
        assert!(
            (fd - kw[i]).norm() < 1e-6 * scale,
            "point {i}: {fd:?} vs {:?}",
            kw[i]
        );
    }
    // Forces sum to zero (momentum) and energy is positive away from rest.
    let mut f = vec![Vector3::zeros(); x.len()];
    let e = net.add_forces(&x, k, &mut f);
    assert!(e > 0.0 && (e - net.energy(&x, k)).abs() < 1e-12 * e);
    assert!(f.iter().sum::<Vector3>().norm() < 1e-12 * scale);
    // The implicit step's fused pass gives the same Hessians, forces − c K w
    // and energy as the separate passes (on top of what `out` holds).
    let c = 0.37;
    let mut fused = vec![Vector3::new(1.0, -2.0, 0.5); x.len()];
    let mut hess2 = SpringHessians::default();
    let e2 = net.add_forces_minus_hessian_product(&x, &w, k, c, &mut fused, &mut hess2);
    assert!((e2 - e).abs() < 1e-12 * e);
    let mut kw2 = vec![Vector3::zeros(); x.len()];
    net.add_hessian_product(&hess2, &w, &mut kw2);
    for i in 0..x.len() {
        let want = Vector3::new(1.0, -2.0, 0.5) + f[i] - kw[i] * c;
        assert!((fused[i] - want).norm() < 1e-12 * scale, "point {i}");
        assert!((kw2[i] - kw[i]).norm() < 1e-12 * scale, "point {i}");
    }
}

#[test]
fn bench_sculpt_rejects_absurd_arguments() {
    let dir = tempfile::tempdir().unwrap();
    for args in [["--steps", "0"], ["--dt", "NaN"], ["--dt", "5"]] {
        let out = common::run_subdyn(dir.path(), &["bench", "sculpt", args[0], args[1]]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}

#[test]
fn the_update_as_printed_gains_energy_where_symplectic_euler_does_not() {
    // McDonnell & Qin §4.3 write p_{i+1} = p_i + ṗ_i Δt (forward Euler):
    // without damping every oscillation grows. The default (symplectic)
    // update keeps the energy bounded at the same step.
    let run = |scheme: ExplicitScheme| {
        let params = SolidParams {
            level: 1,
            damping: 0.0,
            scheme,
            ..SolidParams::default()
        };
        let mut s = Solid::new(&cube(), params).unwrap();
        perturb(&mut s, 0.05);
        let e0 = s.energy();
        let mut range: (Real, Real) = (1.0, 1.0);
        for _ in 0..1000 {
            s.step_explicit(1e-3).unwrap();
            let r = s.energy() / e0;
            range = (range.0.min(r), range.1.max(r));
        }
        range
    };
    let symplectic = run(ExplicitScheme::SymplecticEuler);
    let forward = run(ExplicitScheme::ForwardEuler);
    assert!(symplectic.0 > 0.8 && symplectic.1 < 1.25, "{symplectic:?}");
    assert!(forward.1 > 2.0, "{forward:?}");
}

/// A deformed, moving level-2 cube with two fixed control points and a
/// taut rope, so that every term of the implicit system is present.
fn loaded_cube(preconditioner: ImplicitPreconditioner, cg_tolerance: Real) -> Solid {
    let params = SolidParams {
        level: 2,
        cg_tolerance,
        preconditioner,
        ..SolidParams::default()
    };
    let mut s = Solid::new(&cube(), params).unwrap();
    perturb(&mut s, 0.2);
    s.set_fixed(&[0, 1], true).unwrap();
    let corner = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(corner, Point3::new(1.6, 1.4, 1.5), 80.0, 0.0)
        .unwrap();
    s
}

#[test]
fn a_fresh_lagged_hessian_preconditioner_solves_its_step_in_one_iteration() {
    // When built, the preconditioner is the step's own matrix
    // A₁ᵀ((1 + hγ)M + h²K)A₁ (springs, rope, fixed points): one CG
    // iteration reaches a tight tolerance. The spring Laplacian cannot.
    let tol = 1e-11;
    let mut s = loaded_cube(ImplicitPreconditioner::LaggedHessian, tol);
    let r = s.step_implicit(1e-2).unwrap();
    assert!(r.refreshed, "the first step builds the preconditioner");
    assert_eq!(r.iterations, 1, "residual {:.2e}", r.residual);
    assert!(r.residual <= tol, "residual {:.2e}", r.residual);
    // The next step reuses it (lagged by one step) and still converges.
    let r = s.step_implicit(1e-2).unwrap();
    assert!(!r.refreshed);
    assert!(r.residual <= tol && r.iterations >= 1);
    let mut l = loaded_cube(ImplicitPreconditioner::Laplacian, tol);
    let r = l.step_implicit(1e-2).unwrap();
    assert!(r.iterations > 3, "Laplacian: {} iterations", r.iterations);
    // A refresh threshold of zero iterations is refused.
    let params = SolidParams {
        preconditioner_refresh: 0,
        ..SolidParams::default()
    };
    assert!(Solid::new(&cube(), params).is_err());
}

#[test]
fn both_preconditioners_give_the_same_trajectory() {
    // The preconditioner changes the CG iterates, not the backward-Euler
    // system: 60 steps with either agree to far below the motion.
    let tol = 1e-10;
    let mut runs = Vec::new();
    for pre in [
        ImplicitPreconditioner::Laplacian,
        ImplicitPreconditioner::LaggedHessian,
    ] {
        let mut s = loaded_cube(pre, tol);
        let start = s.control_points().to_vec();
        let (mut refreshed, mut reused) = (0, 0);
        for _ in 0..60 {
            let r = s.step_implicit(1e-2).unwrap();
            assert!(r.residual <= tol);
            if r.refreshed {
                refreshed += 1;
            } else {
                reused += 1;
            }
        }
        if pre == ImplicitPreconditioner::LaggedHessian {
            assert!(refreshed >= 1 && reused >= 1, "{refreshed} / {reused}");
        }
        let moved = max_move(&start, s.control_points());
        assert!(moved > 0.05, "the solid barely moved ({moved})");
        runs.push(s.control_points().to_vec());
    }
    let diff = max_move(&runs[0], &runs[1]);
    assert!(diff < 1e-7, "trajectories differ by {diff:.2e}");
}

//! Surface fine tuning: edge loops, the energy's gradient, α ≡ 1 is the
//! identity, energy decreases monotonically, fixed vertices stay put, edges
//! with values above 1 get longer; and the `subdyn finetune surface` /
//! `subdyn subdivide --scheme` command lines with bad inputs.

mod common;

use std::process::Output;

use common::run_subdyn as subdyn;
use subdyn::finetune::{
    REFINEMENT_ITERATIONS, SurfaceFineTune, SurfaceFineTuneParams, SurfaceScheme,
    doo_sabin_to_non_uniform, edge_loops,
};
use subdyn::math::{Point3, Vector3};
use subdyn::topology::Level;

/// The cube's top vertex 7 = (1, 1, 1) and its three edges at 1.3; the bottom
/// vertices 0, 1, 4 (y = 0) fixed (figure 16 of the paper in spirit).
fn figure16() -> (Vec<(u32, u32, f64)>, Vec<u32>) {
    (vec![(7, 3, 1.3), (7, 5, 1.3), (7, 6, 1.3)], vec![0, 1, 4])
}

#[test]
fn every_edge_is_in_exactly_one_loop() {
    let c = doo_sabin_to_non_uniform(&subdyn::examples::cube(), 0.05).unwrap();
    let loops = edge_loops(&c.level);
    let mut seen = vec![0; c.level.num_edges()];
    for l in &loops {
        assert!(l.closed);
        assert_eq!(l.vertices.len(), l.edges.len());
        for (k, &e) in l.edges.iter().enumerate() {
            seen[e as usize] += 1;
            let [a, b] = c.level.edge_verts[e as usize];
            let (p, q) = (l.vertices[k], l.vertices[(k + 1) % l.vertices.len()]);
            assert!(
                (a, b) == (p, q) || (a, b) == (q, p),
                "loop legs must be its edges"
            );
        }
        // Loops alternate face edges (interval ε) and vertex edges (interval 1).
        for k in 0..l.edges.len() {
            let (e0, e1) = (l.edges[k], l.edges[(k + 1) % l.edges.len()]);
            assert_ne!(c.edge_kind[e0 as usize], c.edge_kind[e1 as usize]);
        }
    }
    assert!(seen.iter().all(|&s| s == 1));
}

#[test]
fn energy_gradient_matches_finite_differences() {
    let (values, fixed) = figure16();
    let p = SurfaceFineTune::new(
        &subdyn::examples::cube(),
        SurfaceScheme::DooSabin,
        &values,
        &fixed,
        &SurfaceFineTuneParams::default(),
    )
    .unwrap();
    // A perturbed configuration in unit-cube coordinates.
    let x: Vec<Point3> = p
        .mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let s = (i as f64 * 0.7).sin() * 0.03;
            Point3::new(q.x - 0.5 + s, q.y - 0.5 - s, q.z - 0.5 + 0.5 * s)
        })
        .collect();
    let (_, g) = p.energy.energy_and_gradient(&x, true);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for v in 0..x.len() {
        for k in 0..3 {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[v][k] += h;
            xm[v][k] -= h;
            let fd = (p.energy.energy(&xp) - p.energy.energy(&xm)) / (2.0 * h);
            worst = worst.max((fd - g[v][k]).abs());
        }
    }
    assert!(
        worst < 1e-6,
        "gradient differs from finite differences by {worst}"
    );
}

#[test]
fn unit_values_leave_the_surface_unchanged() {
    for scheme in [SurfaceScheme::DooSabin, SurfaceScheme::CatmullClark] {
        for mesh in [
            subdyn::examples::cube(),
            subdyn::examples::torus(6, 4, 2.0, 0.6),
        ] {
            let p =
                SurfaceFineTune::new(&mesh, scheme, &[], &[0], &SurfaceFineTuneParams::default())
                    .unwrap();
            let (out, report) = p.solve().unwrap();
            assert!(
                report.energies[0] < 1e-20,
                "α ≡ 1 energy {}",
                report.energies[0]
            );
            let moved = out
                .positions
                .iter()
                .zip(&p.mesh.positions)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(moved < 1e-9, "α ≡ 1 moved a vertex by {moved}");
        }
    }
}

#[test]
fn energy_decreases_and_fixed_vertices_stay_put() {
    let (values, fixed) = figure16();
    let cube = subdyn::examples::cube();
    let p = SurfaceFineTune::new(
        &cube,
        SurfaceScheme::DooSabin,
        &values,
        &fixed,
        &SurfaceFineTuneParams::default(),
    )
    .unwrap();
    let (out, report) = p.solve().unwrap();
    let e = &report.energies;
    assert!(e.len() > 5, "only {} energies recorded", e.len());
    for k in 1..e.len() {
        assert!(
            e[k] <= e[k - 1] * (1.0 + 1e-12),
            "energy rose at iteration {k}: {} -> {}",
            e[k - 1],
            e[k]
        );
    }
    assert!(*e.last().unwrap() < 0.7 * e[0]);
    // Converted vertices are corners of the cube; corner c belongs to vertex face_verts[c].
    let mut checked = 0;
    for (c, &v) in cube.face_vertices.iter().enumerate() {
        if fixed.contains(&v) {
            assert_eq!(out.positions[c], p.mesh.positions[c]);
            checked += 1;
        }
    }
    assert_eq!(checked, 9);
    // The F-legs of the three edges at 1.3 got longer, on average by more than 10 %.
    let level = &p.level;
    let mut ratios = Vec::new();
    for (e, &[a, b]) in level.edge_verts.iter().enumerate() {
        let (va, vb) = (
            cube.face_vertices[a as usize],
            cube.face_vertices[b as usize],
        );
        if p.intervals[e] < 1.0
            && values
                .iter()
                .any(|&(i, j, _)| (i, j) == (va, vb) || (j, i) == (va, vb))
        {
            let l0 = (p.mesh.positions[b as usize] - p.mesh.positions[a as usize]).norm();
            let l1 = (out.positions[b as usize] - out.positions[a as usize]).norm();
            ratios.push(l1 / l0);
        }
    }
    assert_eq!(ratios.len(), 6);
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!(mean > 1.1, "legs at 1.3 grew only by {mean}");
}

/// Steps solved with the previous factor (`refinement_iterations`) reach the
/// same minimum as factoring every step: same energy to 1e-10 (relative),
/// same vertices to 1e-7 of the unit-cube scale, monotone energies.
#[test]
fn reusing_the_factor_reaches_the_same_surface() {
    let (n, m) = (8usize, 6usize);
    let mesh = subdyn::examples::torus(n, m, 2.0, 0.7);
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let values: Vec<(u32, u32, f64)> = (0..m).map(|j| (id(0, j), id(0, j + 1), 1.3)).collect();
    let fixed: Vec<u32> = (0..m).map(|j| id(n / 2, j)).collect();
    let solve = |refinement_iterations| {
        let params = SurfaceFineTuneParams {
            refinement_iterations,
            ..Default::default()
        };
        SurfaceFineTune::new(&mesh, SurfaceScheme::DooSabin, &values, &fixed, &params)
            .unwrap()
            .solve()
            .unwrap()
    };
    let (exact, r_exact) = solve(0);
    let (reused, r_reused) = solve(REFINEMENT_ITERATIONS);
    assert_eq!(r_exact.solver_timings.refined[0], 0);
    assert!(
        r_reused.solver_timings.refined[0] > 0,
        "no step was solved from an earlier factor: {:?}",
        r_reused.solver_timings
    );
    assert!(r_reused.solver_timings.factorizations < r_exact.solver_timings.factorizations);
    assert!(r_reused.energies.windows(2).all(|w| w[1] < w[0]));
    let (e0, e1) = (
        r_exact.energies.last().unwrap(),
        r_reused.energies.last().unwrap(),
    );
    assert!((e0 - e1).abs() <= 1e-10 * e0, "energies {e0} vs {e1}");
    let d = exact
        .positions
        .iter()
        .zip(&reused.positions)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(d < 1e-7 * 5.4, "vertices differ by {d}");
}

#[test]
fn bad_parameters_are_refused() {
    let cube = subdyn::examples::cube();
    let params = SurfaceFineTuneParams::default();
    let dos = SurfaceScheme::DooSabin;
    assert!(SurfaceFineTune::new(&cube, dos, &[(0, 7, 1.3)], &[], &params).is_err());
    assert!(SurfaceFineTune::new(&cube, dos, &[(7, 3, f64::NAN)], &[], &params).is_err());
    assert!(SurfaceFineTune::new(&cube, dos, &[(7, 3, -1.0)], &[], &params).is_err());
    assert!(SurfaceFineTune::new(&cube, dos, &[], &[99], &params).is_err());
    let bad_k = SurfaceFineTuneParams {
        k: [0.0; 3],
        ..Default::default()
    };
    assert!(SurfaceFineTune::new(&cube, dos, &[], &[], &bad_k).is_err());
    let bad_eps = SurfaceFineTuneParams {
        epsilon: f64::INFINITY,
        ..Default::default()
    };
    assert!(SurfaceFineTune::new(&cube, dos, &[], &[], &bad_eps).is_err());
    let _ = Vector3::zeros();
}

// ---------------------------------------------------------------- CLI

fn fails_with(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure, stderr: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    assert!(err.contains(needle), "expected '{needle}' in: {err}");
}

#[test]
fn cli_finetune_surface_runs_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = subdyn(d, &["subdivide", "--levels", "0", "-o", "cube.obj"]);
    assert!(out.status.success());
    std::fs::write(
        d.join("v.json"),
        r#"{"default": 1, "edges": [[7,3,1.3],[7,5,1.3],[7,6,1.3]]}"#,
    )
    .unwrap();
    let out = subdyn(
        d,
        &[
            "finetune",
            "surface",
            "cube.obj",
            "--edge-values",
            "v.json",
            "--fix",
            "0,2,4",
            "-o",
            "ft.obj",
            "--report",
            "r.json",
            "--knots-out",
            "ft.knots",
            "--refined",
            "ft3.obj",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let ft = subdyn::io::read_mesh(d.join("ft.obj")).unwrap();
    assert_eq!(ft.num_vertices(), 24);
    Level::from_mesh(&ft).unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("r.json")).unwrap()).unwrap();
    assert!(report["report"]["iterations"].as_u64().unwrap() > 0);
    // The knot file feeds `subdivide --scheme non-uniform`, which matches --refined.
    let out = subdyn(
        d,
        &[
            "subdivide",
            "ft.obj",
            "--scheme",
            "non-uniform",
            "--knots",
            "ft.knots",
            "--levels",
            "3",
            "-o",
            "again.obj",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (a, b) = (
        subdyn::io::read_mesh(d.join("ft3.obj")).unwrap(),
        subdyn::io::read_mesh(d.join("again.obj")).unwrap(),
    );
    assert_eq!(a.num_vertices(), b.num_vertices());
    let diff = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(diff < 1e-5, "refined outputs differ by {diff}");

    // Bad inputs: one line, non-zero exit, no output file.
    for (name, text) in [
        ("bad.json", r#"{"edges": [[7, 3]]}"#),
        ("bad2.json", r#"{"edges": [[0, 7, 1.3]]}"#),
        ("bad3.json", "not json"),
        ("bad4.json", r#"{"default": -2}"#),
    ] {
        std::fs::write(d.join(name), text).unwrap();
    }
    let cases: [(&str, &str, &[&str], &str); 8] = [
        ("cube.obj", "bad.json", &[], "bad.json"),
        ("cube.obj", "bad2.json", &[], "not joined"),
        ("cube.obj", "bad3.json", &[], "JSON"),
        ("cube.obj", "bad4.json", &[], "control value"),
        ("cube.obj", "v.json", &["--fix", "99"], "fixed vertex 99"),
        ("cube.obj", "v.json", &["--k", "1,1"], "three values"),
        ("cube.obj", "v.json", &["-o", "x.txt"], "x.txt"),
        ("missing.obj", "v.json", &[], "missing.obj"),
    ];
    for (mesh, values, extra, needle) in cases {
        let mut args = vec!["finetune", "surface", mesh, "--edge-values", values];
        args.extend_from_slice(extra);
        if !extra.contains(&"-o") {
            args.extend_from_slice(&["-o", "x.obj"]);
        }
        fails_with(&subdyn(d, &args), needle);
    }
    assert!(!d.join("x.obj").exists());
}

#[test]
fn cli_subdivide_schemes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = subdyn(
        d,
        &[
            "subdivide",
            "--scheme",
            "doo-sabin",
            "--levels",
            "1",
            "-o",
            "ds.obj",
        ],
    );
    assert!(out.status.success());
    assert_eq!(
        subdyn::io::read_mesh(d.join("ds.obj")).unwrap().num_faces(),
        26
    );
    // Non-uniform with no knot file is uniform Catmull-Clark.
    assert!(
        subdyn(
            d,
            &[
                "subdivide",
                "--scheme",
                "non-uniform",
                "--levels",
                "2",
                "-o",
                "nu.obj"
            ]
        )
        .status
        .success()
    );
    assert!(
        subdyn(d, &["subdivide", "--levels", "2", "-o", "cc.obj"])
            .status
            .success()
    );
    let (a, b) = (
        subdyn::io::read_mesh(d.join("nu.obj")).unwrap(),
        subdyn::io::read_mesh(d.join("cc.obj")).unwrap(),
    );
    let diff = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(diff < 1e-6);
    std::fs::write(d.join("k.txt"), "0 7 1\n").unwrap();
    fails_with(
        &subdyn(
            d,
            &[
                "subdivide",
                "--scheme",
                "non-uniform",
                "--knots",
                "k.txt",
                "-o",
                "y.obj",
            ],
        ),
        "not joined",
    );
    std::fs::write(d.join("k2.txt"), "0 1 -1\n").unwrap();
    fails_with(
        &subdyn(
            d,
            &[
                "subdivide",
                "--scheme",
                "non-uniform",
                "--knots",
                "k2.txt",
                "-o",
                "y.obj",
            ],
        ),
        "k2.txt",
    );
    fails_with(
        &subdyn(
            d,
            &[
                "subdivide",
                "--scheme",
                "doo-sabin",
                "--limit",
                "-o",
                "y.obj",
            ],
        ),
        "--limit",
    );
    assert!(!d.join("y.obj").exists());
}

#[test]
fn open_and_mixed_meshes_fine_tune_without_trouble() {
    // An open 4×4 grid (boundary: open loops) and a pentagonal prism with two
    // triangles (n-gons and triangles: approximate conversion).
    let k = 4usize;
    let positions: Vec<Point3> = (0..k * k)
        .map(|v| Point3::new((v / k) as f64, (v % k) as f64, 0.1 * ((v * 7) % 5) as f64))
        .collect();
    let id = |i: usize, j: usize| (i * k + j) as u32;
    let faces: Vec<Vec<u32>> = (0..k - 1)
        .flat_map(|i| {
            (0..k - 1).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    let grid = subdyn::mesh::PolyMesh::from_faces(positions, &faces).unwrap();
    let mut prism_faces = vec![vec![4, 3, 2, 1, 0], vec![5, 6, 7, 8, 9]];
    for a in 0..5u32 {
        let b = (a + 1) % 5;
        if a == 2 {
            prism_faces.push(vec![a, b, b + 5]);
            prism_faces.push(vec![a, b + 5, a + 5]);
        } else {
            prism_faces.push(vec![a, b, b + 5, a + 5]);
        }
    }
    let prism_positions: Vec<Point3> = (0..10)
        .map(|v| {
            let t = std::f64::consts::TAU * (v % 5) as f64 / 5.0;
            Point3::new(t.cos(), t.sin(), if v < 5 { 0.0 } else { 1.2 })
        })
        .collect();
    let prism = subdyn::mesh::PolyMesh::from_faces(prism_positions, &prism_faces).unwrap();
    for (mesh, values, fixed) in [
        (
            grid,
            vec![(id(1, 1), id(1, 2), 1.4), (id(2, 1), id(2, 2), 1.4)],
            vec![0u32, 3, 12],
        ),
        (prism, vec![(5, 6, 1.3), (6, 7, 1.3)], vec![0, 1, 2]),
    ] {
        for scheme in [SurfaceScheme::DooSabin, SurfaceScheme::CatmullClark] {
            let p = SurfaceFineTune::new(
                &mesh,
                scheme,
                &values,
                &fixed,
                &SurfaceFineTuneParams::default(),
            )
            .unwrap();
            let (out, report) = p.solve().unwrap();
            let e = &report.energies;
            assert!(e[0] > 0.0);
            assert!(
                e.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-12)),
                "energy rose"
            );
            assert!(*e.last().unwrap() < e[0]);
            assert!(
                out.positions
                    .iter()
                    .all(|q| q.coords.iter().all(|c| c.is_finite()))
            );
        }
    }
}

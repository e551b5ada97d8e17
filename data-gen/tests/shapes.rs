//! `data-gen shape`: every built-in shape is a closed, consistently oriented
//! manifold with the right Euler characteristic, loads back through subdyn's
//! readers and agrees with its analytic facts.

mod common;

use std::collections::HashMap;

use common::{json, ok, scratch};
use subdyn::io::read_mesh;
use subdyn::mesh::PolyMesh;

/// `V − E + F`, checking on the way that every edge has exactly two faces
/// using it in opposite directions (closed, edge-manifold, oriented).
fn euler_characteristic_of_closed_oriented(mesh: &PolyMesh) -> i64 {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in mesh.faces() {
        for i in 0..f.len() {
            *directed.entry((f[i], f[(i + 1) % f.len()])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "directed edge {a}->{b} used {n} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} has no opposite half"
        );
    }
    let edges = directed.len() / 2;
    mesh.num_vertices() as i64 - edges as i64 + mesh.num_faces() as i64
}

/// Signed volume `(1/6) Σ a · (b × c)` over fan triangles.
fn volume(mesh: &PolyMesh) -> f64 {
    mesh.faces()
        .map(|f| {
            let p = |i: usize| mesh.positions[f[i] as usize].coords;
            (1..f.len() - 1)
                .map(|i| p(0).dot(&p(i).cross(&p(i + 1))) / 6.0)
                .sum::<f64>()
        })
        .sum()
}

#[test]
fn every_shape_is_closed_with_the_right_euler_characteristic() {
    let dir = scratch("shapes");
    for (name, chi) in [
        ("sphere", 2),
        ("ellipsoid", 2),
        ("torus", 0),
        ("genus2", -2),
        ("bulb", 2),
        ("anvil", 2),
        ("plate", 0),
        ("bracket", -6),
        ("chair", -8),
    ] {
        let out = format!("{name}.obj");
        ok(&dir, &["shape", name, "-o", &out]);
        let mesh = read_mesh(dir.join(&out)).expect("the mesh loads back");
        assert_eq!(
            euler_characteristic_of_closed_oriented(&mesh),
            chi,
            "{name}"
        );
        assert!(volume(&mesh) > 0.0, "{name}: faces point outwards");
        let side = json(&dir.join(format!("{name}.json")));
        let t = &side["ground_truth"]["topology"];
        assert_eq!(t["euler_characteristic"], chi, "{name} sidecar");
        assert_eq!(t["genus"], (2 - chi) / 2, "{name} sidecar");
        assert_eq!(t["closed_manifold"], true, "{name} sidecar");
        assert_eq!(t["vertices"], mesh.num_vertices(), "{name} sidecar");
        assert_eq!(side["mesh"], out.as_str());
        let dev = side["ground_truth"]["max_vertex_distance_to_analytic_surface"]
            .as_f64()
            .unwrap();
        assert!(
            dev < 1e-9,
            "{name}: vertices on the analytic surface, off by {dev}"
        );
    }
}

#[test]
fn sphere_and_torus_match_their_formulas() {
    let dir = scratch("formulas");
    ok(
        &dir,
        &[
            "shape",
            "sphere",
            "-o",
            "s.ply",
            "--radius",
            "2",
            "--resolution",
            "32",
        ],
    );
    let s = read_mesh(dir.join("s.ply")).unwrap();
    assert_eq!(s.num_faces(), 6 * 32 * 32);
    for p in &s.positions {
        assert!((p.coords.norm() - 2.0).abs() < 1e-12);
    }
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
    assert!((volume(&s) - exact).abs() < 0.005 * exact);
    let side = json(&dir.join("s.json"));
    assert!((side["ground_truth"]["analytic"]["volume"].as_f64().unwrap() - exact).abs() < 1e-12);

    ok(
        &dir,
        &[
            "shape", "torus", "-o", "t.off", "--major", "2", "--minor", "0.5",
        ],
    );
    let t = read_mesh(dir.join("t.off")).unwrap();
    for p in &t.positions {
        let q = (p.x * p.x + p.y * p.y).sqrt() - 2.0;
        assert!(((q * q + p.z * p.z).sqrt() - 0.5).abs() < 1e-12);
    }
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25;
    assert!((volume(&t) - exact).abs() < 0.005 * exact);

    ok(
        &dir,
        &["shape", "ellipsoid", "-o", "e.obj", "--radii", "3,2,1"],
    );
    let e = read_mesh(dir.join("e.obj")).unwrap();
    for p in &e.positions {
        let r = (p.x / 3.0).powi(2) + (p.y / 2.0).powi(2) + p.z * p.z;
        assert!((r - 1.0).abs() < 1e-12);
    }
}

#[test]
fn a_mesh_file_is_copied_and_described() {
    let dir = scratch("from");
    ok(
        &dir,
        &["shape", "torus", "-o", "t.obj", "--resolution", "12"],
    );
    ok(&dir, &["shape", "--from", "t.obj", "-o", "copy.ply.gz"]);
    let a = read_mesh(dir.join("t.obj")).unwrap();
    let b = read_mesh(dir.join("copy.ply.gz")).unwrap();
    assert_eq!(a, b);
    let side = json(&dir.join("copy.json"));
    assert_eq!(side["ground_truth"]["topology"]["genus"], 1);
    assert_eq!(side["ground_truth"]["source"], "t.obj");
}

#[test]
fn shapes_are_byte_identical_from_run_to_run() {
    let (a, b) = (scratch("same-a"), scratch("same-b"));
    for dir in [&a, &b] {
        ok(
            dir,
            &["shape", "genus2", "-o", "g.obj", "--resolution", "48"],
        );
        ok(dir, &["shape", "bulb", "-o", "b.ply"]);
    }
    for f in ["g.obj", "g.json", "b.ply", "b.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
}

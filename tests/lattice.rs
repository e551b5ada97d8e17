//! Volume lattices and Catmull-Clark volume refinement (MacCracken & Joy 1996):
//! topology checks, JSON, stencil invariants, the cube, tricubic reproduction.

mod common;

use common::Rng;
use common::volume::pyramid;
use common::volume::{cubic_bspline, tricubic};
use subdyn::lattice::{
    Lattice, LatticeBuilder, LatticeHierarchy, LatticeTopology, box_grid, cylinder, extrude,
    hexahedra,
};
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn unit_cube() -> Lattice {
    box_grid(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), [1, 1, 1]).unwrap()
}

fn test_lattices() -> Vec<(&'static str, Lattice)> {
    let mut rng = Rng::new(7);
    let mut grid = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.5), [3, 2, 2]).unwrap();
    for q in &mut grid.positions {
        q.coords += 0.05 * rng.vector();
    }
    vec![
        ("cube", unit_cube()),
        ("grid", grid),
        ("cylinder", cylinder(1.0, 2.0, 6, 2).unwrap()),
        ("pyramid", pyramid()),
    ]
}

#[test]
fn refinement_rows_sum_to_one_and_are_affine_invariant() {
    let mut rng = Rng::new(3);
    for (name, lat) in test_lattices() {
        let h = LatticeHierarchy::new(&lat, 2).unwrap();
        for (k, s) in h.stencils.iter().enumerate() {
            for (r, sum) in s.row_sums().iter().enumerate() {
                assert!(
                    (sum - 1.0).abs() < 1e-12,
                    "{name} level {k} row {r}: sum {sum}"
                );
            }
            assert_eq!(s.num_rows(), h.level(k + 1).topology.num_vertices);
        }
        let s2 = h.stencil_to_level(2).unwrap();
        let (a, b) = common::random_affine(&mut rng);
        let moved = common::affine(&lat.positions, &a, &b);
        let lhs = s2.apply(&moved).unwrap();
        let rhs = common::affine(&s2.apply(&lat.positions).unwrap(), &a, &b);
        let err = common::max_pairwise(&lhs, &rhs);
        assert!(
            err < 1e-12 * common::diag(&rhs),
            "{name}: affine error {err}"
        );
    }
}

#[test]
fn a_cube_lattice_refines_to_exactly_the_cube() {
    let lat = unit_cube();
    let h = LatticeHierarchy::new(&lat, 3).unwrap();
    let levels = h.refine_positions(&lat.positions).unwrap();
    for (k, pos) in levels.iter().enumerate().skip(1) {
        let topo = &h.level(k).topology;
        assert_eq!(topo.num_cells(), 8usize.pow(k as u32));
        // Every boundary vertex on the cube's surface, every vertex inside it.
        for f in topo.boundary_faces() {
            for &v in topo.faces.row(f as usize) {
                let q = pos[v as usize];
                let on = (0..3).any(|i| q[i].abs() < 1e-14 || (q[i] - 1.0).abs() < 1e-14);
                assert!(on, "level {k}: boundary vertex {v} at {q:?} off the cube");
            }
        }
        assert!(
            pos.iter()
                .all(|q| (0..3).all(|i| (-1e-14..=1.0 + 1e-14).contains(&q[i])))
        );
        // The cells fill the cube: their volumes sum to 1.
        let refined = Lattice::new(pos.clone(), topo.clone()).unwrap();
        let vol: f64 = refined.cell_volumes().unwrap().iter().sum();
        assert!(
            (vol - 1.0).abs() < 1e-12,
            "level {k}: cells fill {vol}, not 1"
        );
    }
}

/// Interior refined control points of a regular grid are the knot-inserted
/// tricubic B-spline control points: their limit (mask (1,4,1)/6 per axis)
/// is the B-spline volume at their parameter, evaluated directly.
#[test]
fn a_regular_grid_interior_reproduces_the_tricubic_bspline_volume() {
    let n = [6usize, 6, 6];
    let regular = box_grid(p(0.0, 0.0, 0.0), p(6.0, 6.0, 6.0), n).unwrap();
    let mut rng = Rng::new(11);
    let ctrl: Vec<Point3> = regular
        .positions
        .iter()
        .map(|q| q + 0.3 * rng.vector())
        .collect();
    let levels = 2;
    let h = LatticeHierarchy::new(&regular, levels).unwrap();
    let s = h.stencil_to_level(levels).unwrap();
    let grid_pos = s.apply(&regular.positions).unwrap();
    let refined = s.apply(&ctrl).unwrap();
    let scale = (1 << levels) as f64;
    // Index refined vertices by their (exact, in the interior) grid position.
    let m = 6 * (1 << levels);
    let mut index = vec![usize::MAX; (m + 1) * (m + 1) * (m + 1)];
    for (v, q) in grid_pos.iter().enumerate() {
        let ijk = [q.x * scale, q.y * scale, q.z * scale];
        if ijk.iter().all(|x| (x - x.round()).abs() < 1e-9) {
            let [i, j, k] = ijk.map(|x| x.round() as usize);
            index[i + (m + 1) * (j + (m + 1) * k)] = v;
        }
    }
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    // Parameters in [2, 4]: the support [1, 5] holds only interior vertices.
    for k in 2 * (1 << levels)..=4 * (1 << levels) {
        for j in 2 * (1 << levels)..=4 * (1 << levels) {
            for i in 2 * (1 << levels)..=4 * (1 << levels) {
                let mut limit = Point3::origin();
                for (dk, dj, di) in (0..27).map(|t| (t / 9, (t / 3) % 3, t % 3)) {
                    let w = cubic_bspline(di as f64 - 1.0)
                        * cubic_bspline(dj as f64 - 1.0)
                        * cubic_bspline(dk as f64 - 1.0);
                    let id = (i + di - 1) + (m + 1) * ((j + dj - 1) + (m + 1) * (k + dk - 1));
                    assert_ne!(index[id], usize::MAX, "grid point {i},{j},{k} not found");
                    limit.coords += w * refined[index[id]].coords;
                }
                let t = [i as f64 / scale, j as f64 / scale, k as f64 / scale];
                let exact = tricubic(&ctrl, n, t);
                worst = worst.max((limit - exact).norm());
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 9 * 9 * 9);
    assert!(
        worst < 1e-12,
        "refined grid differs from the tricubic B-spline by {worst}"
    );
}

#[test]
fn type_n_cells_appear_only_at_valence_n_vertices_and_double() {
    let h = LatticeHierarchy::new(&pyramid(), 3).unwrap();
    for k in 1..=3 {
        let t = h.level(k).type_n.as_ref().unwrap();
        let count = |n: usize| (0..t.len()).filter(|&c| t.valence(c) == n).count();
        // The pyramid has four valence-3 base vertices and a valence-4 apex.
        assert_eq!(count(4), 1 << (k - 1), "level {k}: type-4 cells");
        assert_eq!(
            count(3) + count(4),
            t.len(),
            "level {k}: only types 3 and 4"
        );
        for c in 0..t.len() {
            assert_eq!(t.hexahedron(c).is_some(), t.valence(c) == 3);
        }
    }
    let cyl = LatticeHierarchy::new(&cylinder(1.0, 1.0, 6, 1).unwrap(), 1).unwrap();
    let t = cyl.level(1).type_n.as_ref().unwrap();
    assert!(
        (0..t.len()).all(|c| t.valence(c) == 3),
        "prism corners have valence 3"
    );
}

#[test]
fn builders_make_valid_lattices() {
    let cyl = cylinder(1.0, 2.0, 8, 3).unwrap();
    assert_eq!(cyl.topology.num_cells(), 9 * 3);
    assert_eq!(cyl.num_vertices(), 16 * 4);
    let sq = PolyMesh::from_faces(
        vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, 1.0, 0.0),
        ],
        &[vec![0, 1, 2, 3]],
    )
    .unwrap();
    let bar = extrude(&sq, Vector3::new(0.0, 0.0, 1.0), 4).unwrap();
    assert_eq!(bar.topology.num_cells(), 4);
    assert_eq!(bar.topology.boundary_faces().len(), 4 * 4 + 2);
    let vol: f64 = bar.cell_volumes().unwrap().iter().sum();
    assert!((vol - 4.0).abs() < 1e-12);
    // Cell by cell: a cube and two prisms attached face to face.
    let mut b = LatticeBuilder::default();
    let ids: Vec<u32> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .iter()
        .map(|&(x, y)| b.add_vertex(p(x, y, 0.0)))
        .collect();
    let top = b.attach_cell(&ids, Vector3::new(0.0, 0.0, 1.0)).unwrap();
    let top = b.attach_cell(&top, Vector3::new(0.0, 0.0, 1.0)).unwrap();
    b.attach_cell(&top, Vector3::new(0.2, 0.0, 1.0)).unwrap();
    let l = b.build().unwrap();
    assert_eq!(l.topology.num_cells(), 3);
    assert_eq!(l.topology.boundary_faces().len(), 3 * 4 + 2);
    // Automatic tags of a box: 8 corners, 12 · 1 sharp edges.
    let tags = &unit_cube().tags;
    assert_eq!(tags.corners.iter().filter(|c| **c).count(), 8);
    assert_eq!(tags.sharp_edges.iter().filter(|c| **c).count(), 12);
    let g = box_grid(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), [2, 2, 2]).unwrap();
    assert_eq!(g.tags.corners.iter().filter(|c| **c).count(), 8);
    assert_eq!(g.tags.sharp_edges.iter().filter(|c| **c).count(), 24);
}

fn topo_error(faces: &[Vec<u32>], cells: &[Vec<u32>], n: usize) -> String {
    LatticeTopology::new(n, faces, cells)
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_lattices_are_refused_naming_the_element() {
    let hexf: Vec<Vec<u32>> = subdyn::lattice::HEX_FACES
        .iter()
        .map(|f| f.iter().map(|&i| i as u32).collect())
        .collect();
    // Open cell: a face missing.
    let e = topo_error(&hexf[..5], &[vec![0, 1, 2, 3, 4]], 8);
    assert!(e.contains("cell 0") && e.contains("not closed"), "{e}");
    // A face in three cells.
    let e = topo_error(&hexf, &vec![vec![0, 1, 2, 3, 4, 5]; 3], 8);
    assert!(e.contains("more than two cells"), "{e}");
    // Out of range, repeated face, degenerate face.
    assert!(topo_error(&[vec![0, 1, 9]], &[vec![0]], 4).contains("face 0: vertex 9 out of range"));
    assert!(topo_error(&[vec![0, 1, 2], vec![2, 1, 0]], &[vec![0]], 3).contains("repeats face 0"));
    assert!(topo_error(&[vec![0, 1, 1]], &[vec![0]], 3).contains("distinct"));
    // Two cubes that share nothing.
    let mut pos: Vec<Point3> = Vec::new();
    for dx in [0.0, 5.0] {
        for &(x, y, z) in &[
            (0., 0., 0.),
            (1., 0., 0.),
            (1., 1., 0.),
            (0., 1., 0.),
            (0., 0., 1.),
            (1., 0., 1.),
            (1., 1., 1.),
            (0., 1., 1.),
        ] {
            pos.push(p(x + dx, y, z));
        }
    }
    let e = hexahedra(
        pos.clone(),
        &[[0, 1, 2, 3, 4, 5, 6, 7], [8, 9, 10, 11, 12, 13, 14, 15]],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cell 1") && e.contains("not connected"), "{e}");
    // A flat cell and a NaN.
    let mut flat = pos[..8].to_vec();
    for q in &mut flat[4..] {
        q.z = 0.0;
    }
    let e = hexahedra(flat, &[[0, 1, 2, 3, 4, 5, 6, 7]])
        .unwrap_err()
        .to_string();
    assert!(e.contains("cell 0: degenerate"), "{e}");
    let mut nan = pos[..8].to_vec();
    nan[3].y = f64::NAN;
    let e = hexahedra(nan, &[[0, 1, 2, 3, 4, 5, 6, 7]])
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertex 3") && e.contains("finite"), "{e}");
}

#[test]
fn lattice_json_round_trips_and_reports_bad_files() {
    use std::path::Path;
    use subdyn::io::{lattice_from_json, lattice_to_json, read_lattice, write_lattice};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cyl.json");
    let cyl = cylinder(1.0, 2.0, 5, 2).unwrap();
    write_lattice(&path, &cyl).unwrap();
    let back = read_lattice(&path).unwrap();
    assert_eq!((&back.topology, &back.tags), (&cyl.topology, &cyl.tags));
    assert!(common::max_pairwise(&back.positions, &cyl.positions) < 1e-15);
    // Manual tags survive.
    let mut tagged = unit_cube();
    tagged.tags.corners = vec![false; 8];
    let back = lattice_from_json(lattice_to_json(&tagged).as_bytes(), Path::new("t.json")).unwrap();
    assert_eq!(back.tags, tagged.tags);
    let hex = r#"{"vertices": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
                  "hexahedra": [[0,1,3,2,4,5,7,6]]}"#;
    let lat = lattice_from_json(hex.as_bytes(), Path::new("h.json")).unwrap();
    assert_eq!(lat.topology, unit_cube().topology);
    let bad = |text: &str| {
        lattice_from_json(text.as_bytes(), Path::new("bad.json"))
            .unwrap_err()
            .to_string()
    };
    let e = bad("{\"vertices\": [[0,0,0],\n [1,0]]}");
    assert!(e.starts_with("bad.json:2:"), "{e}");
    let e = bad(r#"{"vertices": [[0,0,0]]}"#);
    assert!(e.contains("expected either"), "{e}");
    let e = bad(&hex.replace("[0,1,3,2,4,5,7,6]", "[0,1,3,2,4,5,7,60]"));
    assert!(e.contains("bad.json") && e.contains("out of range"), "{e}");
    let e = bad(&hex.replace("\"hexahedra\"", "\"hexahedron\""));
    assert!(e.contains("unknown field"), "{e}");
}

#[test]
fn box_lattices_enclose_the_model_and_cull_empty_cells() {
    use subdyn::lattice::{BoxKind, BoxLatticeParams, box_lattice};
    // Points on a thin rotated slab.
    let mut rng = Rng::new(21);
    let rot = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.4, -0.7, 0.2));
    let pts: Vec<Point3> = (0..500)
        .map(|_| {
            rot * p(
                rng.uniform(-2.0, 2.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-0.1, 0.1),
            )
        })
        .collect();
    let volume = |kind, levels, cull| {
        let params = BoxLatticeParams {
            kind,
            octree_levels: levels,
            cull,
            ..Default::default()
        };
        let lat = box_lattice(&pts, &params).unwrap();
        let v: f64 = lat.cell_volumes().unwrap().iter().sum();
        (lat, v)
    };
    let (aabb, v_aabb) = volume(BoxKind::Aabb, 0, true);
    let (obb, v_obb) = volume(BoxKind::Obb, 0, true);
    assert_eq!(aabb.topology.num_cells(), 1);
    assert!(
        v_obb < 0.5 * v_aabb,
        "OBB {v_obb} not tighter than AABB {v_aabb}"
    );
    // The OBB is the slab grown by 5 % of the diagonal: ≈ (4 + 2m)(2 + 2m)(0.2 + 2m).
    let m = 0.05 * common::diag(&pts);
    let expect = (4.0 + 2.0 * m) * (2.0 + 2.0 * m) * (0.2 + 2.0 * m);
    assert!(
        (v_obb - expect).abs() < 0.1 * expect,
        "OBB volume {v_obb}, expected ≈ {expect}"
    );
    let ffd = subdyn::ffd::Ffd::new(
        &obb,
        &pts,
        &subdyn::ffd::FfdParams {
            levels: 1,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(ffd.report.outside, 0, "OBB lattice misses vertices");
    let (full, _) = volume(BoxKind::Obb, 3, false);
    let (culled, _) = volume(BoxKind::Obb, 3, true);
    assert_eq!(full.topology.num_cells(), 512);
    assert!(culled.topology.num_cells() < 512 && culled.topology.num_cells() >= 64);
    assert!(
        box_lattice(
            &pts,
            &BoxLatticeParams {
                octree_levels: 9,
                ..Default::default()
            }
        )
        .is_err()
    );
    assert!(box_lattice(&[], &BoxLatticeParams::default()).is_err());
}

#[test]
fn lattice_cli_writes_a_readable_lattice_and_refuses_bad_input() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cube = subdyn::examples::cube();
    subdyn::io::write_mesh(d.join("m.obj"), &cube, None).unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_subdyn"))
            .args(args)
            .current_dir(d)
            .output()
            .unwrap()
    };
    let out = run(&[
        "lattice",
        "m.obj",
        "-o",
        "lat.json",
        "--box",
        "obb",
        "--octree-levels",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lat = subdyn::io::read_lattice(d.join("lat.json")).unwrap();
    assert!(lat.topology.num_cells() > 8 && lat.topology.num_cells() <= 64);
    let out = run(&[
        "lattice",
        "m.obj",
        "-o",
        "local.json",
        "--octree-levels",
        "1",
        "--shrink",
        "0.01",
        "--refine-cells",
        "0,7",
        "--report",
        "r.json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let local = subdyn::io::read_lattice(d.join("local.json")).unwrap();
    assert_eq!(local.topology.num_cells(), 8 - 2 + 16);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("r.json")).unwrap()).unwrap();
    assert_eq!(report["local_refinement"]["refined"], 2, "{report}");
    assert!(report["shrink"]["moved"].as_u64().unwrap() > 0, "{report}");
    for (args, needle) in [
        (vec!["lattice", "m.obj", "-o", "lat.obj"], "json"),
        (
            vec!["lattice", "m.obj", "-o", "x.json", "--octree-levels", "12"],
            "octree levels",
        ),
        (
            vec!["lattice", "missing.obj", "-o", "x.json"],
            "missing.obj",
        ),
        (
            vec!["lattice", "m.obj", "-o", "x.json", "--refine-cells", "8"],
            "cell 8",
        ),
        (
            vec!["lattice", "m.obj", "-o", "x.json", "--shrink=-1"],
            "shrink",
        ),
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(needle), "`{needle}` not in {err}");
        assert!(!d.join("x.json").exists());
    }
}

/// Every derived incidence of `LatticeTopology::new` recounted by brute
/// force from the face loops and cell face lists alone.
fn assert_incidences_match_a_recount(name: &str, t: &LatticeTopology) {
    use std::collections::BTreeSet;
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for f in 0..t.num_faces() {
        let l = t.faces.row(f);
        for i in 0..l.len() {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            let e = [a.min(b), a.max(b)];
            if !edges.contains(&e) {
                edges.push(e);
            }
            assert_eq!(
                t.edges[t.face_edges.row(f)[i] as usize],
                e,
                "{name}: face {f} edge {i}"
            );
        }
    }
    assert_eq!(t.edges, edges, "{name}: edges in first-appearance order");
    for (e, &[a, b]) in edges.iter().enumerate() {
        let faces: Vec<u32> = (0..t.num_faces() as u32)
            .filter(|&f| {
                let l = t.faces.row(f as usize);
                (0..l.len()).any(|i| {
                    let (x, y) = (l[i], l[(i + 1) % l.len()]);
                    (x, y) == (a, b) || (x, y) == (b, a)
                })
            })
            .collect();
        assert_eq!(
            t.edge_faces.row(e),
            faces.as_slice(),
            "{name}: edge {e} faces"
        );
        let cells: BTreeSet<u32> = (0..t.num_cells() as u32)
            .filter(|&c| t.cells.row(c as usize).iter().any(|f| faces.contains(f)))
            .collect();
        let got: BTreeSet<u32> = t.edge_cells.row(e).iter().copied().collect();
        assert_eq!(got, cells, "{name}: edge {e} cells");
        assert_eq!(
            t.edge_cells.row(e).len(),
            cells.len(),
            "{name}: edge {e} cells repeated"
        );
    }
    for c in 0..t.num_cells() {
        let verts: BTreeSet<u32> = t
            .cells
            .row(c)
            .iter()
            .flat_map(|&f| t.faces.row(f as usize).to_vec())
            .collect();
        let want: Vec<u32> = verts.into_iter().collect();
        assert_eq!(
            t.cell_vertices.row(c),
            want.as_slice(),
            "{name}: cell {c} vertices"
        );
    }
    for v in 0..t.num_vertices {
        let v32 = v as u32;
        let cells: Vec<u32> = (0..t.num_cells() as u32)
            .filter(|&c| t.cell_vertices.row(c as usize).contains(&v32))
            .collect();
        assert_eq!(
            t.vertex_cells.row(v),
            cells.as_slice(),
            "{name}: vertex {v} cells"
        );
        let faces: Vec<u32> = (0..t.num_faces() as u32)
            .filter(|&f| t.faces.row(f as usize).contains(&v32))
            .collect();
        assert_eq!(
            t.vertex_faces.row(v),
            faces.as_slice(),
            "{name}: vertex {v} faces"
        );
        let es: Vec<u32> = (0..edges.len() as u32)
            .filter(|&e| edges[e as usize].contains(&v32))
            .collect();
        assert_eq!(
            t.vertex_edges.row(v),
            es.as_slice(),
            "{name}: vertex {v} edges"
        );
    }
}

#[test]
fn derived_incidences_match_a_brute_force_recount() {
    for (name, lat) in test_lattices() {
        assert_incidences_match_a_recount(name, &lat.topology);
        let h = LatticeHierarchy::new(&lat, 1).unwrap();
        assert_incidences_match_a_recount(name, &h.level(1).topology);
    }
}

// ------------------------------------------------ shrink and local refinement

#[test]
fn a_shrunk_single_box_is_the_model_box_grown_by_the_offset() {
    use subdyn::lattice::{BoxLatticeParams, shrunk_box_lattice};
    let mut rng = Rng::new(11);
    let model: Vec<Point3> = (0..200)
        .map(|_| {
            p(
                rng.uniform(-1.0, 2.0),
                rng.uniform(0.0, 0.5),
                rng.uniform(3.0, 4.0),
            )
        })
        .collect();
    let diag = common::diag(&model);
    let params = BoxLatticeParams {
        margin: 0.2,
        ..Default::default()
    };
    let (lat, report) = shrunk_box_lattice(&model, &params, 0.03).unwrap();
    let (lo, hi) = subdyn::math::bounding_box(&model).unwrap();
    let (llo, lhi) = subdyn::math::bounding_box(&lat.positions).unwrap();
    for k in 0..3 {
        assert!(
            (llo[k] - (lo[k] - 0.03 * diag)).abs() < 1e-12 * diag,
            "axis {k}"
        );
        assert!(
            (lhi[k] - (hi[k] + 0.03 * diag)).abs() < 1e-12 * diag,
            "axis {k}"
        );
    }
    assert_eq!(report.moved, 8);
    assert!((report.max_move - 0.17).abs() < 1e-9, "{report:?}");
}

#[test]
fn shrunk_octree_lattices_move_boundary_points_inwards_only_and_stay_valid() {
    use subdyn::lattice::{BoxLatticeParams, box_lattice, shrunk_box_lattice};
    let sphere: Vec<Point3> = (0..2000)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let a = i as f64 * 2.399_963;
            p(r * a.cos(), r * a.sin(), z)
        })
        .collect();
    for levels in [1, 2, 3] {
        let params = BoxLatticeParams {
            octree_levels: levels,
            ..Default::default()
        };
        let plain = box_lattice(&sphere, &params).unwrap();
        let (lat, report) = shrunk_box_lattice(&sphere, &params, 0.02).unwrap();
        assert_eq!(lat.topology, plain.topology, "K = {levels}: same cells");
        assert!(report.moved > 0, "K = {levels}");
        // Only boundary points move, each axis component into the lattice:
        // towards the centroids of the point's own cells (an inner cavity's
        // boundary moves outwards, towards the shell).
        let mut moved = 0;
        let t = &plain.topology;
        for (v, (a, b)) in plain.positions.iter().zip(&lat.positions).enumerate() {
            if a == b {
                continue;
            }
            moved += 1;
            let on_boundary = t
                .vertex_faces
                .row(v)
                .iter()
                .any(|&f| t.is_boundary_face(f as usize));
            assert!(on_boundary, "K = {levels}, vertex {v}");
            let cs = t.vertex_cells.row(v);
            let inner = cs.iter().fold(Vector3::zeros(), |s, &c| {
                let vs = t.cell_vertices.row(c as usize);
                s + vs.iter().fold(Vector3::zeros(), |s, &w| {
                    s + plain.positions[w as usize].coords
                }) / vs.len() as f64
            }) / cs.len() as f64;
            for k in 0..3 {
                assert!(
                    (b - a)[k] * (inner[k] - a[k]) >= 0.0,
                    "K = {levels}, vertex {v}, axis {k}"
                );
            }
        }
        assert_eq!(moved, report.moved, "K = {levels}");
        // Boundary points keep at least the offset from every model vertex
        // along their axis: no model vertex is cut off by a box face.
        let (lo, hi) = subdyn::math::bounding_box(&lat.positions).unwrap();
        let (mlo, mhi) = subdyn::math::bounding_box(&sphere).unwrap();
        for k in 0..3 {
            assert!(lo[k] <= mlo[k] - 0.02 * common::diag(&sphere) + 1e-9);
            assert!(hi[k] >= mhi[k] + 0.02 * common::diag(&sphere) - 1e-9);
        }
    }
    assert!(shrunk_box_lattice(&sphere, &BoxLatticeParams::default(), f64::NAN).is_err());
}

#[test]
fn local_refinement_makes_the_papers_cells_and_a_valid_lattice() {
    use subdyn::lattice::locally_refined;
    let grid = box_grid(p(0.0, 0.0, 0.0), p(3.0, 3.0, 3.0), [3, 3, 3]).unwrap();
    // The centre cell: 6 face neighbours, 12 edge neighbours, 8 corner neighbours.
    let (lat, r) = locally_refined(&grid, &[13]).unwrap();
    assert_eq!(r.refined, 1);
    assert_eq!(lat.topology.num_cells(), 26 + 8);
    // Face neighbours (9 faces) and edge neighbours (2 pentagons) are not hexahedra.
    assert_eq!(r.non_hexahedral, 6 + 12);
    // Face points have valence 4 in a face neighbour; edge points valence 2
    // in an edge neighbour (and 3 in the two face neighbours at the edge).
    assert_eq!(r.extraordinary_corners, 6 + 12);
    // The children are the unit-cube octants of the centre cell.
    let vols = lat.cell_volumes().unwrap();
    assert!(
        vols[26..].iter().all(|v| (v - 0.125).abs() < 1e-12),
        "{vols:?}"
    );
    assert!((vols.iter().sum::<f64>() - 27.0).abs() < 1e-9);
    incidence_and_refinement_checks(&lat);
    // A corner cell on the boundary, and two cells sharing a face.
    for chosen in [vec![0], vec![4, 13], vec![0, 26]] {
        let (lat, _) = locally_refined(&grid, &chosen).unwrap();
        incidence_and_refinement_checks(&lat);
    }
    // Refining a locally refined lattice again, inside a child.
    let (again, _) = locally_refined(&lat, &[26, 3]).unwrap();
    incidence_and_refinement_checks(&again);
    assert!(locally_refined(&grid, &[27]).is_err());
    assert!(locally_refined(&grid, &[]).is_err());
}

/// Topology recount, and one level of refinement: rows sum to one, type-n
/// cells exactly at the corners of valence `n`.
fn incidence_and_refinement_checks(lat: &Lattice) {
    assert_incidences_match_a_recount("local", &lat.topology);
    let h = LatticeHierarchy::new(lat, 2).unwrap();
    for s in &h.stencils {
        assert!(s.row_sums().iter().all(|x| (x - 1.0).abs() < 1e-12));
    }
    let t = &lat.topology;
    let mut want = std::collections::BTreeMap::new();
    for c in 0..t.num_cells() {
        for &v in t.cell_vertices.row(c) {
            *want
                .entry(t.corner_ring(c, v).unwrap().len() / 2)
                .or_insert(0) += 1;
        }
    }
    let tn = h.level(1).type_n.as_ref().unwrap();
    let mut got = std::collections::BTreeMap::new();
    for c in 0..tn.len() {
        *got.entry(tn.valence(c)).or_insert(0) += 1;
    }
    assert_eq!(got, want);
}

#[test]
fn octree_subdivision_of_a_box_grid_is_the_half_spacing_grid() {
    use subdyn::lattice::{octree_refined, refined_topology};
    let lat = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.5), [2, 1, 3]).unwrap();
    let (fine, o) = octree_refined(&lat).unwrap();
    assert!(o.row_sums().iter().all(|s| (s - 1.0).abs() < 1e-14));
    assert_eq!(fine.topology, refined_topology(&lat.topology).unwrap().0);
    let half = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.5), [4, 2, 6]).unwrap();
    assert_eq!(fine.num_vertices(), half.num_vertices());
    assert!(common::point_set_distance(&fine.positions, &half.positions) < 1e-12);
    // On the rest box both rules give the regular grid (it is linear data);
    // on a perturbed lattice they differ: the gap that hierarchical
    // deformation corrects.
    let h = LatticeHierarchy::new(&lat, 1).unwrap();
    let s = h.stencil_to_level(1).unwrap();
    let gap = |x: &[Point3]| {
        let cc = s.apply(x).unwrap();
        let oc = o.apply(x).unwrap();
        cc.iter()
            .zip(&oc)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    assert!(gap(&lat.positions) < 1e-12);
    let mut rng = Rng::new(4);
    let bent: Vec<Point3> = lat
        .positions
        .iter()
        .map(|q| q + 0.1 * rng.vector())
        .collect();
    let g = gap(&bent);
    assert!(
        g > 1e-3,
        "octree and Catmull-Clark rules agree on a bent lattice: {g}"
    );
}

#[test]
fn compact_refined_cells_match_the_full_refined_topology() {
    use subdyn::lattice::{refined_cells, refined_topology};
    for (name, lat) in test_lattices() {
        let (full, tn) = refined_topology(&lat.topology).unwrap();
        let (cells, boundary) = refined_cells(&lat.topology).unwrap();
        assert_eq!(cells, tn, "{name}");
        let mut want: Vec<Vec<u32>> = full
            .boundary_faces()
            .iter()
            .map(|&f| full.faces.row(f as usize).to_vec())
            .collect();
        let mut got: Vec<Vec<u32>> = boundary.iter().map(|q| q.to_vec()).collect();
        want.sort();
        got.sort();
        assert_eq!(got, want, "{name}");
    }
}

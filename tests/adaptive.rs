//! Adaptive refinement: local Catmull-Clark refinement of marked faces,
//! progressive interpolation of limit points, and the noise test that picks
//! the faces.

mod common;

use common::{Rng, perturbed};
use subdyn::fit::refine_marks::{faces_above_noise, faces_off_data};
use subdyn::limit::{LimitEvaluator, interpolate_limit_points, limit_stencil};
use subdyn::math::Real;
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{
    Hierarchy, LocalRefinement, RefineOptions, Refiner, close_marks, refine_marked,
};
use subdyn::topology::{Level, NONE};

fn uniform(mesh: &PolyMesh) -> Hierarchy {
    Refiner::new(mesh, &RefineOptions::default())
        .unwrap()
        .refine_uniform(1)
        .unwrap()
}

fn local(mesh: &PolyMesh, marks: &[bool]) -> (LocalRefinement, Hierarchy) {
    let h = uniform(mesh);
    let r = refine_marked(mesh, h.level(0), h.stencil(0), marks).unwrap();
    (r, h)
}

/// A closed quad mesh of 96 faces (the cube refined twice), perturbed.
fn fine_cube() -> PolyMesh {
    let mut mesh = subdyn::examples::cube();
    for _ in 0..2 {
        let h = uniform(&mesh);
        let p = h.stencil(0).apply(&mesh.positions).unwrap();
        mesh = h.mesh(1, p);
    }
    perturbed(mesh, 0.02, 7)
}

#[test]
fn marking_every_face_is_uniform_refinement() {
    // Quads, a pentagon and a boundary (mixed_mesh) as well as a closed mesh.
    for mesh in [common::mixed_mesh(), fine_cube()] {
        let (r, h) = local(&mesh, &vec![true; mesh.num_faces()]);
        let p1 = h.stencil(0).apply(&mesh.positions).unwrap();
        assert_eq!(r.mesh.num_vertices(), p1.len());
        for (v, &u) in r.uniform_vertex.iter().enumerate() {
            assert_eq!(r.mesh.positions[v], p1[u as usize], "vertex {v}");
        }
        let lv = h.level(1);
        assert_eq!(r.mesh.num_faces(), lv.num_faces());
        for f in 0..lv.num_faces() {
            let ours: Vec<u32> = r
                .mesh
                .face(f)
                .iter()
                .map(|&v| r.uniform_vertex[v as usize])
                .collect();
            assert_eq!(ours, lv.face_vertices(f), "face {f}");
        }
    }
}

#[test]
fn marking_no_face_changes_nothing() {
    let mesh = fine_cube();
    let (r, _) = local(&mesh, &vec![false; mesh.num_faces()]);
    assert_eq!(r.mesh, mesh);
    assert_eq!(
        r.parent_face,
        (0..mesh.num_faces() as u32).collect::<Vec<_>>()
    );
}

#[test]
fn one_split_face_leaves_a_closed_manifold_with_t_vertices() {
    let mesh = fine_cube();
    let mut marks = vec![false; mesh.num_faces()];
    marks[17] = true;
    let (r, _) = local(&mesh, &marks);
    // One face point and four edge points; the four neighbours across its
    // edges become pentagons.
    assert_eq!(r.mesh.num_vertices(), mesh.num_vertices() + 5);
    assert_eq!(r.mesh.num_faces(), mesh.num_faces() + 3);
    let sizes: Vec<usize> = r.mesh.faces().map(|f| f.len()).collect();
    assert_eq!(sizes.iter().filter(|&&n| n == 5).count(), 4);
    assert_eq!(
        sizes.iter().filter(|&&n| n == 4).count(),
        mesh.num_faces() + 3 - 4
    );
    let level = Level::from_mesh(&r.mesh).unwrap();
    assert!(
        level.edge_faces.iter().all(|f| f[1] != NONE),
        "a hole opened"
    );
    for s in r.stencil.row_sums() {
        assert!((s - 1.0).abs() < 1e-12, "row sum {s}");
    }
}

#[test]
fn the_surface_far_from_split_faces_is_unchanged() {
    let mesh = fine_cube();
    let mut marks = vec![false; mesh.num_faces()];
    marks[17] = true;
    let (r, _) = local(&mesh, &marks);
    let before = LimitEvaluator::new(&Refiner::new(&mesh, &RefineOptions::default()).unwrap());
    let after = LimitEvaluator::new(&Refiner::new(&r.mesh, &RefineOptions::default()).unwrap());
    // Vertices the split moved or added, and the faces whose limit depends on
    // them: those sharing a vertex with a face that touches them.
    let level = Level::from_mesh(&mesh).unwrap();
    let touched: Vec<bool> = (0..mesh.num_faces())
        .map(|f| {
            level.face_vertices(f).iter().any(|&v| {
                level.vertex_faces(v as usize).iter().any(|&g| {
                    level
                        .face_vertices(g as usize)
                        .iter()
                        .any(|&w| level.vertex_faces(w as usize).contains(&17))
                })
            })
        })
        .collect();
    let mut compared = 0;
    for (child, &parent) in r.parent_face.iter().enumerate() {
        let parent = parent as usize;
        if touched[parent] || r.mesh.face(child) != mesh.face(parent) {
            continue;
        }
        let a = before
            .evaluate(parent, 0.3, 0.6, &mesh.positions)
            .unwrap()
            .p;
        let b = after
            .evaluate(child, 0.3, 0.6, &r.mesh.positions)
            .unwrap()
            .p;
        assert!(
            (a - b).norm() < 1e-12,
            "face {parent} moved by {}",
            (a - b).norm()
        );
        compared += 1;
    }
    assert!(compared > 40, "only {compared} faces compared");
}

#[test]
fn closing_marks_splits_faces_with_most_edges_split() {
    // 4 × 4 grid of quads: face (i, j) at index 4 i + j.
    let mesh = common::grid(5, 1);
    let level = Level::from_mesh(&mesh).unwrap();
    let mut marks = vec![false; 16];
    // Around face 5 = (1, 1): three of its neighbours, (1, 0), (1, 2), (0, 1).
    for f in [4, 6, 1] {
        marks[f] = true;
    }
    let closed = close_marks(&level, &marks);
    assert!(closed[5], "three of four edges split: must be split");
    // Face 0 = (0, 0) has two split edges (to 1 and 4): half, kept.
    assert!(!closed[0]);
    // Closing is idempotent.
    assert_eq!(close_marks(&level, &closed), closed);
}

#[test]
fn progressive_interpolation_puts_limit_points_on_targets() {
    let mesh = fine_cube();
    let h = Refiner::new(&mesh, &RefineOptions::default())
        .unwrap()
        .refine_uniform(0)
        .unwrap();
    let l = limit_stencil(&h, 0).unwrap();
    // Targets the limit points of a differently perturbed mesh.
    let other = perturbed(mesh.clone(), 0.05, 11);
    let targets = l.apply(&other.positions).unwrap();
    let all = vec![true; mesh.num_vertices()];
    let mut last = Real::INFINITY;
    for k in [0, 5, 20, 80] {
        let (_, r) =
            interpolate_limit_points(&mesh, &RefineOptions::default(), &targets, &all, k).unwrap();
        assert!(r < last, "{k} iterations: residual {r} not below {last}");
        last = r;
    }
    assert!(last < 1e-6, "residual after 80 iterations {last}");
    // The mesh whose limit points these are is a fixed point.
    let (p, r) =
        interpolate_limit_points(&other, &RefineOptions::default(), &targets, &all, 3).unwrap();
    assert!(r < 1e-12);
    for (a, b) in p.iter().zip(&other.positions) {
        assert!((a - b).norm() < 1e-12);
    }
    // Fixed vertices stay; the movable ones still converge.
    let movable: Vec<bool> = (0..mesh.num_vertices()).map(|v| v % 3 != 0).collect();
    let (p, r) =
        interpolate_limit_points(&mesh, &RefineOptions::default(), &targets, &movable, 200)
            .unwrap();
    for (v, (a, b)) in p.iter().zip(&mesh.positions).enumerate() {
        assert_eq!(a == b, !movable[v], "vertex {v}");
    }
    assert!(r < 1e-6, "residual over the movable vertices {r}");
    assert!(
        interpolate_limit_points(&mesh, &RefineOptions::default(), &targets[1..], &all, 3).is_err()
    );
    assert!(
        interpolate_limit_points(&mesh, &RefineOptions::default(), &targets, &all[1..], 3).is_err()
    );
}

#[test]
fn the_noise_test_finds_the_biased_face() {
    let mut rng = Rng::new(5);
    let normal = |rng: &mut Rng| {
        // Box-Muller.
        let (u, v) = (rng.uniform(1e-12, 1.0), rng.uniform(0.0, 1.0));
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    };
    let (faces, per) = (20, 200);
    let mut face = Vec::new();
    let mut dist = Vec::new();
    for f in 0..faces {
        for _ in 0..per {
            // Face 3 is off by one noise deviation.
            let bias = if f == 3 { 1.0 } else { 0.0 };
            face.push(f as u32);
            dist.push((bias + normal(&mut rng)).abs());
        }
    }
    let mut weight = vec![1.0; dist.len()];
    // An outlier (zero weight) on face 7 is not counted.
    face.push(7);
    dist.push(50.0);
    weight.push(0.0);
    let (marks, sigma) = faces_above_noise(faces, &face, &dist, &weight, Real::INFINITY, 3.0);
    assert!((sigma - 1.0).abs() < 0.15, "noise estimate {sigma}");
    let marked: Vec<usize> = (0..faces).filter(|&f| marks[f]).collect();
    assert_eq!(marked, vec![3]);
    // A smaller noise level from the data themselves takes over.
    let (_, sigma) = faces_above_noise(faces, &face, &dist, &weight, 0.5, 3.0);
    assert_eq!(sigma, 0.5);
    // Faces with too few points are never split.
    let (marks, _) = faces_above_noise(1, &[0, 0], &[9.0, 9.0], &[1.0, 1.0], 1.0, 0.0);
    assert!(!marks[0]);
}

/// A web across a gap: surface samples of faces 2 and 5 lie far from the
/// data, which no data point's residual shows; the off-data test finds
/// exactly those faces, relative to the median sample distance.
#[test]
fn the_off_data_test_finds_webs() {
    let mut rng = Rng::new(9);
    let mut face = Vec::new();
    let mut dist = Vec::new();
    for f in 0..10u32 {
        for k in 0..16 {
            face.push(f);
            let web = (f == 2 && k == 7) || (f == 5 && k < 4);
            dist.push(if web { 5.0 } else { rng.uniform(0.5, 1.5) });
        }
    }
    let marks = faces_off_data(10, &face, &dist, 4.0);
    let marked: Vec<usize> = (0..10).filter(|&f| marks[f]).collect();
    assert_eq!(marked, vec![2, 5]);
    // Scaled data, the same faces; a factor above the web's ratio, none.
    let scaled: Vec<Real> = dist.iter().map(|d| 100.0 * d).collect();
    assert_eq!(faces_off_data(10, &face, &scaled, 4.0), marks);
    assert!(!faces_off_data(10, &face, &dist, 6.0).contains(&true));
    // Off, or nothing to judge by.
    assert!(!faces_off_data(10, &face, &dist, 0.0).contains(&true));
    assert!(!faces_off_data(10, &[], &[], 4.0).contains(&true));
}

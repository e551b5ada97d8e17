//! Integration tests of the limit surface (`subdyn::limit`): agreement with
//! OpenSubdiv 3.6 `Bfr` samples, corners equal vertex limit positions,
//! derivatives agree with finite differences, continuity across face edges,
//! limit stencil row sums, bicubic B-spline reproduction on regular faces,
//! watertight tessellation, closest points, and the limit at dart vertices
//! (an infinitely sharp crease ending inside the mesh).
//!
//! Fixtures: `tests/data/opensubdiv/NAME.bfr.txt` (see its README) and the
//! meshes built in `tests/common/mod.rs`.

mod common;

use common::*;
use std::f64::consts::TAU;
use subdyn::limit::{
    ClosestPointEngine, ClosestPointParams, LimitEvaluator, LimitPoint, PatchTable, Sample,
    cubic_basis, limit_stencil, tessellate,
};
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{BoundaryRule, Refiner};
use subdyn::topology::Level;

/// Positions against OpenSubdiv, relative to the bounding-box diagonal.
const BFR_POS_TOL: f64 = 1e-9;
/// First derivatives against OpenSubdiv, relative to the bounding-box diagonal.
const BFR_DERIV_TOL: f64 = 1e-7;
/// Two exact computations of the same quantity, relative to its scale.
const EXACT_TOL: f64 = 1e-12;
/// Parameter step of the central differences.
const FD_STEP: f64 = 1e-5;
/// Central differences against analytic derivatives, relative to
/// `max(|value|, diag)` (truncation `O(h²)` plus round-off `ε/h`).
const FD_TOL: f64 = 1e-6;
/// Distance from sample points to the edges and corners of their quad or
/// quad sub-face (in that patch's unit parameter).
const FD_MARGIN: f64 = 0.05;
/// Parameter distance from a corner at which the limit must already agree
/// with the corner's limit position to 1e-9·diag.
const CORNER_APPROACH: f64 = 1e-12;
/// Closest-point distance error (absolute; the meshes have diagonal ≈ 1.7–3).
const CP_DIST_TOL: f64 = 1e-9;

/// Evaluates the limit at every line of `NAME.bfr.txt`; returns the largest
/// position and derivative errors relative to the bounding-box diagonal.
fn check_bfr(name: &str) -> (f64, f64) {
    let mesh = reference_mesh(name);
    let d = diag(&mesh.positions);
    let eval = LimitEvaluator::new(&default_refiner(&mesh));
    let samples = read_bfr(&opensubdiv(&format!("{name}.bfr.txt")));
    assert_eq!(
        samples.len(),
        25 * mesh.num_faces(),
        "{name}: a 5×5 grid per face"
    );
    let (mut ep, mut ed) = (0.0f64, 0.0f64);
    let (mut wp, mut wd) = (None, None);
    for s in &samples {
        let e = eval.evaluate(s.face, s.u, s.v, &mesh.positions).unwrap();
        let p = (e.p - s.p).norm() / d;
        let q = (e.du - s.du).norm().max((e.dv - s.dv).norm()) / d;
        if p > ep {
            (ep, wp) = (p, Some((s.face, s.u, s.v)));
        }
        if q > ed {
            (ed, wd) = (q, Some((s.face, s.u, s.v)));
        }
    }
    println!(
        "{name}: Bfr max error position {ep:.3e}·diag at {wp:?}, derivatives {ed:.3e}·diag at {wd:?}"
    );
    assert!(
        ep <= BFR_POS_TOL,
        "{name}: limit positions differ from Bfr by {ep:e}·diag at (face, u, v) = {wp:?}"
    );
    assert!(
        ed <= BFR_DERIV_TOL,
        "{name}: first derivatives differ from Bfr by {ed:e}·diag at (face, u, v) = {wd:?}"
    );
    (ep, ed)
}

#[test]
fn cube_limit_samples_match_bfr() {
    check_bfr("cube");
}

#[test]
fn fan5_open_limit_samples_match_bfr() {
    check_bfr("fan5_open");
}

#[test]
fn grid4_open_limit_samples_match_bfr() {
    check_bfr("grid4_open");
}

#[test]
fn torus_regular_limit_samples_match_bfr() {
    check_bfr("torus_regular");
}

// ---------------------------------------------------------------------------
// Corners

/// Limit evaluation at every corner of every face against the vertex limit
/// positions of `limit_stencil(h, 0)`, and against evaluation `CORNER_APPROACH`
/// away from the corner inside the face (the limit is continuous there).
fn check_corners(mesh: &PolyMesh, r: &Refiner, name: &str) {
    let d = diag(&mesh.positions);
    let h = r.refine_uniform(0).unwrap();
    let lp = limit_stencil(&h, 0)
        .unwrap()
        .apply(&mesh.positions)
        .unwrap();
    // With a level below, vertices of n-gons and semi-sharp vertices take
    // their vertex points' masks there: the same limit points.
    let deeper = limit_stencil(&r.refine_uniform(1).unwrap(), 0)
        .unwrap()
        .apply(&mesh.positions)
        .unwrap();
    for (v, (a, b)) in lp.iter().zip(&deeper).enumerate() {
        let err = (a - b).norm() / d;
        assert!(
            err <= EXACT_TOL,
            "{name}: vertex {v}: {a} by evaluation, {b} by the masks a level below ({err:e}·diag)"
        );
    }
    let eval = LimitEvaluator::new(r);
    for f in 0..mesh.num_faces() {
        let fv = mesh.face(f);
        for (i, &v) in fv.iter().enumerate() {
            let (u, w) = corner_param(fv.len(), i);
            let p = eval.evaluate(f, u, w, &mesh.positions).unwrap().p;
            let err = (p - lp[v as usize]).norm() / d;
            assert!(
                err <= EXACT_TOL,
                "{name}: face {f} corner {i} (vertex {v}) at ({u}, {w}): {p} vs vertex limit {} ({err:e}·diag)",
                lp[v as usize]
            );
            let (nu, nw) = near_corner_param(fv.len(), i, CORNER_APPROACH);
            let near = eval.evaluate(f, nu, nw, &mesh.positions).unwrap().p;
            let err = (p - near).norm() / d;
            assert!(
                err <= 1e-9,
                "{name}: face {f} corner {i} (vertex {v}): {p} at the corner, {near} at ({nu}, {nw}) ({err:e}·diag)"
            );
        }
    }
}

#[test]
fn face_corners_evaluate_to_vertex_limit_positions() {
    for name in ["cube", "fan5_open"] {
        let mesh = reference_mesh(name);
        check_corners(&mesh, &default_refiner(&mesh), name);
    }
    let pyramid = pentagonal_pyramid();
    check_corners(&pyramid, &default_refiner(&pyramid), "pentagonal pyramid");
    let mixed = mixed_mesh();
    check_corners(&mixed, &default_refiner(&mixed), "mixed mesh");
    for rule in [BoundaryRule::EdgeAndCorner, BoundaryRule::EdgeOnly] {
        check_corners(
            &mixed,
            &refiner(&mixed, rule, &mixed_creases_without_darts()),
            &format!("creased mixed mesh, {rule:?}"),
        );
        let fan = reference_mesh("fan5_open");
        check_corners(
            &fan,
            &refiner(&fan, rule, &[]),
            &format!("fan5_open, {rule:?}"),
        );
    }
}

// ---------------------------------------------------------------------------
// Derivatives

/// `(P, Pu, Pv, Puu, Puv, Pvv)` as an array of vectors.
fn quantities(e: &LimitPoint) -> [Vector3; 6] {
    [e.p.coords, e.du, e.dv, e.duu, e.duv, e.dvv]
}

const NAMES: [&str; 6] = ["P", "Pu", "Pv", "Puu", "Puv", "Pvv"];

/// Central differences of every derivative at random points of every face,
/// and the same samples through `stencils()`; returns the worst relative error.
fn check_derivatives(mesh: &PolyMesh, r: &Refiner, name: &str, seed: u64) -> f64 {
    let d = diag(&mesh.positions);
    let eval = LimitEvaluator::new(r);
    let x = &mesh.positions;
    let at = |f: usize, u: f64, v: f64| eval.evaluate(f, u, v, x).unwrap();
    let mut rng = Rng::new(seed);
    let h = FD_STEP;
    let mut samples = Vec::new();
    let mut values = Vec::new();
    let mut worst: f64 = 0.0;
    for f in 0..mesh.num_faces() {
        let n = mesh.face(f).len();
        for _ in 0..4 {
            let (u, v) = random_param(&mut rng, n, FD_MARGIN);
            let e = at(f, u, v);
            let (up, um, vp, vm) = (
                at(f, u + h, v),
                at(f, u - h, v),
                at(f, u, v + h),
                at(f, u, v - h),
            );
            let c = |a: Vector3, b: Vector3| (a - b) / (2.0 * h);
            let fd = [
                (1, c(up.p.coords, um.p.coords)),
                (2, c(vp.p.coords, vm.p.coords)),
                (3, c(up.du, um.du)),
                (4, c(vp.du, vm.du)),
                (4, c(up.dv, um.dv)),
                (5, c(vp.dv, vm.dv)),
            ];
            let q = quantities(&e);
            for (k, approx) in fd {
                let err = (q[k] - approx).norm() / q[k].norm().max(d);
                worst = worst.max(err);
                assert!(
                    err <= FD_TOL,
                    "{name}: face {f} at ({u}, {v}): {} = {:?}, central difference {:?} (error {err:e})",
                    NAMES[k],
                    q[k],
                    approx
                );
            }
            samples.push(Sample {
                face: f as u32,
                u,
                v,
            });
            values.push(q);
        }
    }
    // The stencil tables give the same numbers as evaluate().
    let st = eval.stencils(&samples).unwrap();
    let tables = [&st.p, &st.du, &st.dv, &st.duu, &st.duv, &st.dvv];
    for (k, t) in tables.iter().enumerate() {
        assert_eq!(t.num_rows(), samples.len());
        assert_eq!(t.num_cols, x.len());
        let got = t.apply(x).unwrap();
        for (i, g) in got.iter().enumerate() {
            let want = values[i][k];
            let err = (g.coords - want).norm() / want.norm().max(d);
            assert!(
                err <= EXACT_TOL,
                "{name}: stencils().{} row {i} = {g} but evaluate() gives {want:?}",
                NAMES[k]
            );
        }
    }
    println!("{name}: worst finite-difference error {worst:.2e}");
    worst
}

#[test]
fn derivatives_match_finite_differences() {
    let cube = reference_mesh("cube");
    check_derivatives(&cube, &default_refiner(&cube), "cube", 1);
    let fan = reference_mesh("fan5_open");
    check_derivatives(&fan, &default_refiner(&fan), "fan5_open", 2);
    let mixed = mixed_mesh();
    check_derivatives(&mixed, &default_refiner(&mixed), "mixed mesh", 3);
    let pyramid = pentagonal_pyramid();
    check_derivatives(
        &pyramid,
        &default_refiner(&pyramid),
        "pentagonal pyramid",
        4,
    );
    let semi: Vec<(u32, u32, f64)> = mixed_creases()
        .into_iter()
        .filter(|c| c.2 < INFINITE)
        .collect();
    check_derivatives(
        &mixed,
        &refiner(&mixed, BoundaryRule::EdgeAndCorner, &semi),
        "semi-sharp mixed mesh",
        5,
    );
    check_derivatives(
        &mixed,
        &refiner(&mixed, BoundaryRule::EdgeAndCorner, &mixed_creases()),
        "creased mixed mesh",
        6,
    );
    check_derivatives(
        &fan,
        &refiner(&fan, BoundaryRule::EdgeOnly, &[]),
        "fan5_open edge-only",
        7,
    );
    check_derivatives(
        &mixed,
        &refiner(&mixed, BoundaryRule::EdgeOnly, &[]),
        "mixed mesh edge-only",
        8,
    );
}

// ---------------------------------------------------------------------------
// Continuity and stencil sums

/// Both faces of every interior edge agree on the limit point and on the
/// tangent along the edge.
fn check_continuity(mesh: &PolyMesh, r: &Refiner, name: &str) {
    let d = diag(&mesh.positions);
    let eval = LimitEvaluator::new(r);
    let l = &r.level;
    let mut checked = 0;
    for e in 0..l.num_edges() {
        if l.is_boundary_edge(e) {
            continue;
        }
        let [f0, f1] = l.edge_faces[e].map(|f| f as usize);
        let k0 = l
            .face_edge_list(f0)
            .iter()
            .position(|&x| x as usize == e)
            .unwrap();
        let k1 = l
            .face_edge_list(f1)
            .iter()
            .position(|&x| x as usize == e)
            .unwrap();
        let (n0, n1) = (l.face_vertices(f0).len(), l.face_vertices(f1).len());
        for tau in [0.0, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0] {
            let ((u0, v0), (du0, dv0)) = edge_param(n0, k0, tau);
            // The edge runs the other way in the second face.
            let ((u1, v1), (du1, dv1)) = edge_param(n1, k1, 1.0 - tau);
            let a = eval.evaluate(f0, u0, v0, &mesh.positions).unwrap();
            let b = eval.evaluate(f1, u1, v1, &mesh.positions).unwrap();
            let err = (a.p - b.p).norm() / d;
            assert!(
                err <= EXACT_TOL,
                "{name}: edge {e} at τ={tau}: face {f0} gives {}, face {f1} gives {} ({err:e}·diag)",
                a.p,
                b.p
            );
            // dP/dτ seen from both faces (opposite directions of τ).
            let ta = a.du * du0 + a.dv * dv0;
            let tb = -(b.du * du1 + b.dv * dv1);
            let err = (ta - tb).norm() / ta.norm().max(d);
            assert!(
                err <= 1e-9,
                "{name}: edge {e} at τ={tau}: tangent along the edge {ta:?} (face {f0}) vs {tb:?} (face {f1})"
            );
            // Tangent planes agree across edges that are not creased.
            if r.sharpness.edge[e] == 0.0 {
                let (na, nb) = (a.normal(), b.normal());
                assert!(
                    na.dot(&nb) > 1.0 - 1e-9,
                    "{name}: edge {e} at τ={tau}: normal {na:?} (face {f0}) vs {nb:?} (face {f1})"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 0);
}

#[test]
fn limit_surface_is_continuous_across_face_edges() {
    let cube = perturbed(subdyn::examples::cube(), 0.1, 9);
    check_continuity(&cube, &default_refiner(&cube), "cube");
    let mixed = mixed_mesh();
    check_continuity(&mixed, &default_refiner(&mixed), "mixed mesh");
    let pyramid = pentagonal_pyramid();
    check_continuity(&pyramid, &default_refiner(&pyramid), "pentagonal pyramid");
    check_continuity(
        &mixed,
        &refiner(&mixed, BoundaryRule::EdgeOnly, &mixed_creases()),
        "creased mixed mesh",
    );
}

/// Limit positions of level-1 vertices (`limit_stencil`) against evaluation
/// at the matching parameters: face points at the face centre (an n-gon's
/// centroid is corner 2 of every sub-face), edge points at edge midpoints,
/// vertex points at the corners.
fn check_level1_limits(mesh: &PolyMesh, r: &Refiner, name: &str) {
    let d = diag(&mesh.positions);
    let h = r.refine_uniform(1).unwrap();
    let lp = limit_stencil(&h, 1)
        .unwrap()
        .apply(&mesh.positions)
        .unwrap();
    let eval = LimitEvaluator::new(r);
    let l = &r.level;
    let (nf, ne) = (l.num_faces(), l.num_edges());
    let check = |idx: usize, f: usize, (u, v): (f64, f64), what: &str| {
        let p = eval.evaluate(f, u, v, &mesh.positions).unwrap().p;
        let err = (p - lp[idx]).norm() / d;
        assert!(
            err <= EXACT_TOL,
            "{name}: {what}: limit_stencil gives {}, evaluate(face {f}, {u}, {v}) gives {p} ({err:e}·diag)",
            lp[idx]
        );
    };
    for f in 0..nf {
        check(f, f, (0.5, 0.5), &format!("face point {f}"));
    }
    for e in 0..ne {
        let f = l.edge_faces[e][0] as usize;
        let k = l
            .face_edge_list(f)
            .iter()
            .position(|&x| x as usize == e)
            .unwrap();
        let (uv, _) = edge_param(l.face_vertices(f).len(), k, 0.5);
        check(nf + e, f, uv, &format!("edge point {e}"));
    }
    for f in 0..nf {
        let fv = l.face_vertices(f);
        for (i, &v) in fv.iter().enumerate() {
            check(
                nf + ne + v as usize,
                f,
                corner_param(fv.len(), i),
                &format!("vertex point {v}"),
            );
        }
    }
}

#[test]
fn limit_stencil_of_level_1_matches_evaluation_at_centres_and_midpoints() {
    let mixed = mixed_mesh();
    for rule in [BoundaryRule::EdgeAndCorner, BoundaryRule::EdgeOnly] {
        check_level1_limits(
            &mixed,
            &refiner(&mixed, rule, &[]),
            &format!("mixed {rule:?}"),
        );
        check_level1_limits(
            &mixed,
            &refiner(&mixed, rule, &mixed_creases_without_darts()),
            &format!("creased mixed {rule:?}"),
        );
    }
    let pyramid = pentagonal_pyramid();
    check_level1_limits(&pyramid, &default_refiner(&pyramid), "pyramid");
    let fan = reference_mesh("fan5_open");
    check_level1_limits(
        &fan,
        &refiner(&fan, BoundaryRule::EdgeOnly, &[]),
        "fan5_open edge-only",
    );
}

#[test]
fn limit_stencil_rows_sum_to_one_and_derivative_rows_to_zero() {
    let mixed = mixed_mesh();
    for rule in [BoundaryRule::EdgeAndCorner, BoundaryRule::EdgeOnly] {
        let r = refiner(&mixed, rule, &mixed_creases());
        let h = r.refine_uniform(2).unwrap();
        for k in 0..=2 {
            let t = limit_stencil(&h, k).unwrap();
            assert_eq!(t.num_rows(), h.level(k).num_vertices);
            for (i, s) in t.row_sums().iter().enumerate() {
                assert!(
                    (s - 1.0).abs() <= EXACT_TOL,
                    "{rule:?}: limit_stencil level {k} row {i} sums to {s}"
                );
            }
        }
        let eval = LimitEvaluator::new(&r);
        let mut rng = Rng::new(21);
        let mut samples = Vec::new();
        for f in 0..mixed.num_faces() {
            let n = mixed.face(f).len();
            for i in 0..n {
                let (u, v) = corner_param(n, i);
                samples.push(Sample {
                    face: f as u32,
                    u,
                    v,
                });
            }
            for _ in 0..5 {
                let (u, v) = random_param(&mut rng, n, 0.0);
                samples.push(Sample {
                    face: f as u32,
                    u,
                    v,
                });
            }
        }
        let st = eval.stencils(&samples).unwrap();
        for (k, t) in [&st.p, &st.du, &st.dv, &st.duu, &st.duv, &st.dvv]
            .iter()
            .enumerate()
        {
            let want = if k == 0 { 1.0 } else { 0.0 };
            for (i, s) in t.row_sums().iter().enumerate() {
                let scale: f64 = t.row(i).1.iter().map(|w| w.abs()).sum::<f64>().max(1.0);
                assert!(
                    (s - want).abs() <= EXACT_TOL * scale,
                    "{rule:?}: {} row {i} ({:?}) sums to {s}, expected {want}",
                    NAMES[k],
                    samples[i]
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Regular faces are bicubic B-spline patches

#[test]
fn regular_face_is_the_bicubic_b_spline_of_its_16_points() {
    let n = 8;
    let mesh = grid(n, 17);
    let d = diag(&mesh.positions);
    let eval = LimitEvaluator::new(&default_refiner(&mesh));
    let mut rng = Rng::new(4);
    let mut checked = 0;
    for i in 1..n - 2 {
        for j in 1..n - 2 {
            let f = i * (n - 1) + j;
            assert_eq!(
                mesh.face(f)[0],
                grid_id(n, i, j),
                "face numbering of the grid fixture"
            );
            for _ in 0..3 {
                let (u, v) = (rng.next_f64(), rng.next_f64());
                let e = eval.evaluate(f, u, v, &mesh.positions).unwrap();
                let (bu, bv) = (cubic_basis(u), cubic_basis(v));
                // (derivative order in u, in v) of P, Pu, Pv, Puu, Puv, Pvv.
                let orders = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
                let q = quantities(&e);
                for (k, &(a, b)) in orders.iter().enumerate() {
                    let mut want = Vector3::zeros();
                    for (x, wu) in bu[a].iter().enumerate() {
                        for (y, wv) in bv[b].iter().enumerate() {
                            let c = mesh.positions[grid_id(n, i + x - 1, j + y - 1) as usize];
                            want += wu * wv * c.coords;
                        }
                    }
                    let err = (q[k] - want).norm() / d;
                    assert!(
                        err <= EXACT_TOL,
                        "face {f} at ({u}, {v}): {} = {:?}, B-spline gives {want:?}",
                        NAMES[k],
                        q[k]
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 75);
}

// ---------------------------------------------------------------------------
// Tessellation

/// Checks that a tessellation is a closed manifold of Euler characteristic
/// 2, that its points are exactly the expected limit samples and that its
/// normals are unit, outward (convex control mesh) and equal the evaluated ones.
fn check_closed_tessellation(mesh: &PolyMesh, k: usize, name: &str) {
    let r = default_refiner(mesh);
    let (tess, normals) = tessellate(&r, &mesh.positions, k).unwrap();
    assert_eq!(
        normals.len(),
        tess.num_vertices(),
        "{name}: one normal per vertex"
    );
    let level = Level::from_mesh(&tess)
        .unwrap_or_else(|e| panic!("{name}: tessellation is not a manifold: {e}"));
    for e in 0..level.num_edges() {
        assert!(
            !level.is_boundary_edge(e),
            "{name}: tessellation edge {:?} has one face",
            level.edge_verts[e]
        );
    }
    for v in 0..level.num_vertices {
        assert!(!level.is_boundary_vertex(v), "{name}: boundary vertex {v}");
        assert!(
            !level.vertex_faces(v).is_empty(),
            "{name}: unused vertex {v}"
        );
    }
    let euler = level.num_vertices as i64 - level.num_edges() as i64 + level.num_faces() as i64;
    assert_eq!(euler, 2, "{name}: Euler characteristic of the tessellation");

    // Expected samples: quads on a k×k grid, or every quad sub-face on a k×k
    // grid when the mesh has a non-quad face.
    let eval = LimitEvaluator::new(&r);
    let split = mesh.faces().any(|f| f.len() != 4);
    let mut expect: Vec<(Point3, Vector3)> = Vec::new();
    for f in 0..mesh.num_faces() {
        let n = mesh.face(f).len();
        let (origins, size): (Vec<(f64, f64)>, f64) = if !split {
            (vec![(0.0, 0.0)], 1.0)
        } else if n == 4 {
            (vec![(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)], 0.5)
        } else {
            ((0..n).map(|i| tile_origin(n, i)).collect(), 0.5)
        };
        for (tu, tv) in origins {
            for a in 0..=k {
                for b in 0..=k {
                    let (u, v) = (
                        tu + size * a as f64 / k as f64,
                        tv + size * b as f64 / k as f64,
                    );
                    let e = eval.evaluate(f, u, v, &mesh.positions).unwrap();
                    expect.push((e.p, e.normal()));
                }
            }
        }
    }
    let pts: Vec<Point3> = expect.iter().map(|x| x.0).collect();
    let d = diag(&mesh.positions);
    let err = point_set_distance(&tess.positions, &pts) / d;
    assert!(
        err <= EXACT_TOL,
        "{name}: tessellation points are {err:e}·diag off the limit samples"
    );

    let centroid = Point3::from(
        mesh.positions.iter().map(|p| p.coords).sum::<Vector3>() / mesh.num_vertices() as f64,
    );
    for (i, (p, n)) in tess.positions.iter().zip(&normals).enumerate() {
        assert!(
            (n.norm() - 1.0).abs() < 1e-9,
            "{name}: normal {i} has length {}",
            n.norm()
        );
        assert!(
            n.dot(&(p - centroid)) > 0.0,
            "{name}: normal {i} at {p} points inwards"
        );
        // The evaluated normal of the nearest expected sample.
        let (_, en) = expect
            .iter()
            .min_by(|a, b| (a.0 - p).norm().total_cmp(&(b.0 - p).norm()))
            .unwrap();
        assert!(
            n.dot(en) > 1.0 - 1e-9,
            "{name}: normal {i} at {p} is {n:?}, evaluate() gives {en:?}"
        );
    }
}

#[test]
fn closed_meshes_tessellate_watertight_on_the_limit_surface() {
    let cube = subdyn::examples::cube();
    check_closed_tessellation(&cube, 4, "cube");
    let (tess, _) = tessellate(&default_refiner(&cube), &cube.positions, 4).unwrap();
    assert_eq!(tess.num_faces(), 6 * 16);
    assert_eq!(tess.num_vertices(), 6 * 16 + 2);
    check_closed_tessellation(&triangular_prism(), 3, "triangular prism");
    check_closed_tessellation(&pentagonal_pyramid(), 2, "pentagonal pyramid");
}

// ---------------------------------------------------------------------------
// Closest points

/// Points on the limit surface (random, and within 1e-3 in parameter of
/// every face corner) offset along the normal by ±d: the engine must find
/// distance d and a sample that re-evaluates to the point it returns.
fn check_offsets(mesh: &PolyMesh, name: &str) {
    let r = default_refiner(mesh);
    let x = &mesh.positions;
    let d = diag(x);
    let eval = LimitEvaluator::new(&r);
    let engine = ClosestPointEngine::new(&r, x, &ClosestPointParams::default()).unwrap();
    let mut rng = Rng::new(12);
    let mut params = Vec::new();
    for f in 0..mesh.num_faces() {
        let n = mesh.face(f).len();
        for _ in 0..3 {
            params.push((f, random_param(&mut rng, n, 0.0)));
        }
        for i in 0..n {
            // Within 1e-3 (in parameter) of corner i, inside the face.
            let eps = rng.uniform(1e-5, 1e-3);
            params.push((f, near_corner_param(n, i, eps)));
        }
    }
    let mut queries = Vec::new();
    let mut expect = Vec::new();
    for (k, &(f, (u, v))) in params.iter().enumerate() {
        let e = eval.evaluate(f, u, v, x).unwrap();
        let nrm = e.normal();
        assert!(
            (nrm.norm() - 1.0).abs() < 1e-9,
            "{name}: no normal at face {f} ({u}, {v})"
        );
        let off = [1e-3, 4e-3, 1e-2][k % 3] * d * if k % 2 == 0 { 1.0 } else { -1.0 };
        queries.push(e.p + off * nrm);
        expect.push((f, u, v, e.p, off.abs()));
    }
    let found = engine.closest_points(&queries).unwrap();
    let mut worst: f64 = 0.0;
    for ((q, cp), &(f, u, v, p, dist)) in queries.iter().zip(&found).zip(&expect) {
        worst = worst.max((cp.distance - dist).abs());
        assert!(
            (cp.distance - dist).abs() <= CP_DIST_TOL,
            "{name}: query {q} above face {f} ({u}, {v}) = {p} at distance {dist}: engine says {} at {} ({:?})",
            cp.distance,
            cp.point,
            cp.sample
        );
        assert!(
            ((cp.point - q).norm() - cp.distance).abs() <= EXACT_TOL * d,
            "{name}: distance inconsistent"
        );
        let back = eval
            .evaluate(cp.sample.face as usize, cp.sample.u, cp.sample.v, x)
            .unwrap()
            .p;
        assert!(
            (back - cp.point).norm() <= EXACT_TOL * d,
            "{name}: sample {:?} evaluates to {back}, engine returned {}",
            cp.sample,
            cp.point
        );
        let single = engine.closest_point(*q).unwrap();
        assert!(
            (single.distance - cp.distance).abs() <= EXACT_TOL * d,
            "{name}: batch and single queries differ"
        );
    }
    println!(
        "{name}: {} offset queries, worst distance error {worst:.2e}",
        queries.len()
    );
}

/// Random far and inside points: the engine's distance is at most the
/// brute-force minimum over a dense tessellation (k = 32).
fn check_against_tessellation(mesh: &PolyMesh, name: &str) {
    let r = default_refiner(mesh);
    let x = &mesh.positions;
    let engine = ClosestPointEngine::new(&r, x, &ClosestPointParams::default()).unwrap();
    let (tess, _) = tessellate(&r, x, 32).unwrap();
    let spacing = (0..tess.num_faces())
        .flat_map(|f| {
            let fv = tess.face(f);
            (0..4).map(move |i| (fv[i], fv[(i + 1) % 4]))
        })
        .map(|(a, b)| (tess.positions[a as usize] - tess.positions[b as usize]).norm())
        .fold(0.0, f64::max);
    let (lo, hi) = subdyn::math::bounding_box(x).unwrap();
    let ext = hi - lo;
    let mut rng = Rng::new(99);
    let queries: Vec<Point3> = (0..60)
        .map(|_| {
            Point3::new(
                lo.x + ext.x * rng.uniform(-1.0, 2.0),
                lo.y + ext.y * rng.uniform(-1.0, 2.0),
                lo.z + ext.z.max(0.5) * rng.uniform(-1.0, 2.0),
            )
        })
        .collect();
    let found = engine.closest_points(&queries).unwrap();
    let mut farther = Vec::new();
    for (q, cp) in queries.iter().zip(&found) {
        let brute = tess
            .positions
            .iter()
            .map(|p| (p - q).norm())
            .fold(f64::INFINITY, f64::min);
        if cp.distance > brute + CP_DIST_TOL {
            farther.push(format!(
                "{q}: engine {} at {:?} > brute-force {brute}",
                cp.distance, cp.sample
            ));
        }
        assert!(
            cp.distance >= brute - 2.0 * spacing,
            "{name}: query {q}: engine distance {} far below the tessellation's {brute}",
            cp.distance
        );
    }
    assert!(
        farther.is_empty(),
        "{name}: {} of {} queries end farther than the nearest vertex of the k=32 tessellation:\n{}",
        farther.len(),
        queries.len(),
        farther.join("\n")
    );
}

#[test]
fn closest_point_recovers_normal_offsets_near_extraordinary_vertices() {
    check_offsets(&subdyn::examples::cube(), "cube");
    check_offsets(&reference_mesh("fan5_open"), "fan5_open");
    check_offsets(&pentagonal_pyramid(), "pentagonal pyramid");
    check_offsets(&mixed_mesh(), "mixed mesh");
}

#[test]
fn closest_point_is_no_farther_than_a_dense_tessellation() {
    check_against_tessellation(&subdyn::examples::cube(), "cube");
    check_against_tessellation(&pentagonal_pyramid(), "pentagonal pyramid");
}

#[test]
fn closest_point_on_an_open_surface_is_no_farther_than_a_dense_tessellation() {
    check_against_tessellation(&reference_mesh("fan5_open"), "fan5_open");
}

/// A query whose nearest limit point lies on the open boundary of fan5_open
/// (face 2, u = 1, v ≈ 0.4325): the engine must reach it, where the
/// derivative of the distance along the boundary vanishes.
#[test]
fn closest_point_slides_along_an_open_boundary() {
    let mesh = reference_mesh("fan5_open");
    let r = default_refiner(&mesh);
    let x = &mesh.positions;
    let eval = LimitEvaluator::new(&r);
    let engine = ClosestPointEngine::new(&r, x, &ClosestPointParams::default()).unwrap();
    let q = Point3::new(-2.861087877106896, 1.696466191677075, 0.5737373413482424);
    // Dense search along the boundary edge u = 1 of face 2.
    let (best, v_best) = (0..=4000)
        .map(|i| {
            let v = i as f64 / 4000.0;
            ((eval.evaluate(2, 1.0, v, x).unwrap().p - q).norm(), v)
        })
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
    let cp = engine.closest_point(q).unwrap();
    let e = eval
        .evaluate(cp.sample.face as usize, cp.sample.u, cp.sample.v, x)
        .unwrap();
    let slope_v = e.dv.dot(&(e.p - q)) / cp.distance;
    assert!(
        cp.distance <= best + CP_DIST_TOL,
        "engine stops at {:?}, distance {} (∂dist/∂v = {slope_v:e}); the boundary point at v = {v_best} is at {best}",
        cp.sample,
        cp.distance
    );
}

// ---------------------------------------------------------------------------
// Darts: an infinitely sharp crease that ends inside the mesh

/// A 5×5-vertex grid with an infinitely sharp crease from the boundary
/// vertex (0, 2) to the centre (2, 2), which is a dart; returns the mesh, the
/// refiner, the dart vertex and a face having the dart as corner 0.
fn dart_grid() -> (PolyMesh, Refiner, usize, usize) {
    let n = 5;
    let mesh = grid(n, 3);
    let c = |i, j| grid_id(n, i, j);
    let creases = [(c(0, 2), c(1, 2), INFINITE), (c(1, 2), c(2, 2), INFINITE)];
    let r = refiner(&mesh, BoundaryRule::EdgeAndCorner, &creases);
    let face = 2 * (n - 1) + 2;
    assert_eq!(mesh.face(face)[0], c(2, 2));
    (mesh, r, c(2, 2) as usize, face)
}

/// The limit of a vertex is the limit of its vertex point: `limit_stencil`
/// must give the same point for the dart at levels 0…4.
#[test]
fn dart_vertex_limit_does_not_depend_on_the_level() {
    let (mesh, r, v, _) = dart_grid();
    let x = &mesh.positions;
    let d = diag(x);
    let h = r.refine_uniform(4).unwrap();
    let at: Vec<Point3> = (0..=4)
        .map(|k| limit_stencil(&h, k).unwrap().apply(x).unwrap()[descendant(&h, k, v)])
        .collect();
    for k in 1..=4 {
        assert!(
            (at[k] - at[0]).norm() <= EXACT_TOL * d,
            "dart limit from level {k} is {}, from level 0 {} (levels 0..4: {at:?})",
            at[k],
            at[0]
        );
    }
}

/// Evaluation exactly at a dart corner must agree with evaluation 1e-12 away
/// (the position exactly; the normal up to the corner-derivative convention).
#[test]
fn limit_is_continuous_at_a_dart_vertex() {
    let (mesh, r, _, f) = dart_grid();
    let x = &mesh.positions;
    let d = diag(x);
    let eval = LimitEvaluator::new(&r);
    let at = eval.evaluate(f, 0.0, 0.0, x).unwrap();
    let near = eval.evaluate(f, 1e-12, 1e-12, x).unwrap();
    assert!(
        (at.p - near.p).norm() <= 1e-9 * d,
        "dart corner evaluates to {}, but 1e-12 away to {} ({:e}·diag)",
        at.p,
        near.p,
        (at.p - near.p).norm() / d
    );
    // Derivatives exactly at an irregular corner follow OpenSubdiv Bfr's
    // level-2 convention (the parametric derivative has no limit there), so
    // the normal they give is close to, not equal to, the limit normal.
    let angle = at
        .normal()
        .dot(&near.normal())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    assert!(
        angle < 5.0,
        "dart corner normal {:?}, 1e-12 away {:?} ({angle}°)",
        at.normal(),
        near.normal()
    );
}

/// Vertex limit tangents: on a regular torus they are the patch derivatives
/// at the corner; at a cube corner (valence 3) they span the symmetric
/// tangent plane, normal to (1, 1, 1).
#[test]
fn vertex_limit_tangents_span_the_tangent_plane() {
    use subdyn::limit::limit_tangent_stencils;
    let torus = subdyn::examples::torus(8, 6, 1.0, 0.4);
    let r = default_refiner(&torus);
    let h = r.refine_uniform(1).unwrap();
    let (t1, t2) = limit_tangent_stencils(&h, 0).unwrap();
    let (a, b) = (
        t1.apply(&torus.positions).unwrap(),
        t2.apply(&torus.positions).unwrap(),
    );
    let eval = LimitEvaluator::new(&r);
    for v in 0..torus.num_vertices() {
        let f = r.level.vertex_ring(v).faces[0] as usize;
        let i = torus.face(f).iter().position(|&x| x as usize == v).unwrap();
        let c = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][i];
        let e = eval.evaluate(f, c.0, c.1, &torus.positions).unwrap();
        // leading edge direction of corner i and trailing edge direction
        let dirs = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
        let (l, t) = (dirs[i], dirs[(i + 3) % 4]);
        let want_a = e.du * l.0 + e.dv * l.1;
        let want_b = -(e.du * t.0 + e.dv * t.1);
        assert!(
            (a[v].coords - want_a).norm() < 1e-12,
            "vertex {v}: lead tangent"
        );
        assert!(
            (b[v].coords - want_b).norm() < 1e-12,
            "vertex {v}: trail tangent"
        );
    }
    let cube = subdyn::examples::cube();
    let h = default_refiner(&cube).refine_uniform(0).unwrap();
    let (t1, t2) = limit_tangent_stencils(&h, 0).unwrap();
    let (a, b) = (
        t1.apply(&cube.positions).unwrap(),
        t2.apply(&cube.positions).unwrap(),
    );
    let n = a[0].coords.cross(&b[0].coords).normalize();
    let diagonal = Vector3::new(1.0, 1.0, 1.0).normalize();
    assert!(
        n.dot(&diagonal).abs() > 1.0 - 1e-12,
        "cube corner normal {n:?}"
    );
    assert!(a[0].coords.norm() > 0.1 && b[0].coords.norm() > 0.1);
}

/// Moving the control points of an engine gives the same answers as building
/// a new engine at the new positions (fitting relies on this).
#[test]
fn closest_point_engine_set_positions_equals_a_fresh_engine() {
    let mesh = reference_mesh("fan5_open");
    let r = default_refiner(&mesh);
    let moved: Vec<Point3> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| p + Vector3::new(0.01 * i as f64, -0.02, 0.03 * (i % 3) as f64))
        .collect();
    let params = ClosestPointParams::default();
    let mut engine = ClosestPointEngine::new(&r, &mesh.positions, &params).unwrap();
    let queries: Vec<Point3> = (0..40)
        .map(|i| {
            let t = i as f64 / 40.0;
            Point3::new(1.5 * (6.0 * t).cos(), 1.5 * (6.0 * t).sin(), 0.5 - t)
        })
        .collect();
    // Warm the quadtrees at the old positions first, then move.
    engine.closest_points(&queries).unwrap();
    engine.set_positions(&moved).unwrap();
    let fresh = ClosestPointEngine::new(&r, &moved, &params).unwrap();
    // A handful of queries before the seed tree is rebuilt takes the
    // seed scan instead; it must find what the tree does.
    let few = engine.closest_points(&queries[..8]).unwrap();
    for (q, a) in queries.iter().zip(&few) {
        let b = fresh.closest_point(*q).unwrap();
        assert!(
            (a.distance - b.distance).abs() < 1e-12 && (a.point - b.point).norm() < 1e-9,
            "{q}: scan {} vs tree {}",
            a.distance,
            b.distance
        );
    }
    for q in &queries {
        let (a, b) = (
            engine.closest_point(*q).unwrap(),
            fresh.closest_point(*q).unwrap(),
        );
        assert!(
            (a.distance - b.distance).abs() < 1e-12,
            "{q}: {} vs {}",
            a.distance,
            b.distance
        );
        assert!(
            (a.point - b.point).norm() < 1e-9,
            "{q}: {} vs {}",
            a.point,
            b.point
        );
    }
    assert!(
        engine.set_positions(&moved[1..]).is_err(),
        "wrong count must be rejected"
    );
}

/// After a small move of the control points, descending from the previous
/// answers alone (`closest_points_local`) finds the same closest points as a
/// full seeded search, and an engine moved by `set_positions` (whose seed
/// tree is rebuilt lazily) answers as a freshly built one.
#[test]
fn local_descents_after_a_small_move_match_full_searches() {
    let mesh = subdyn::examples::cube();
    let r = default_refiner(&mesh);
    let mut engine =
        ClosestPointEngine::new(&r, &mesh.positions, &ClosestPointParams::default()).unwrap();
    let mut rng = Rng::new(5);
    let queries: Vec<Point3> = (0..400)
        .map(|_| {
            Point3::new(
                rng.uniform(-0.3, 1.3),
                rng.uniform(-0.3, 1.3),
                rng.uniform(-0.3, 1.3),
            )
        })
        .collect();
    let before = engine.closest_points(&queries).unwrap();
    let moved: Vec<Point3> = mesh
        .positions
        .iter()
        .map(|p| Point3::new(1.01 * p.x + 0.002, p.y - 0.003 * p.z, 0.99 * p.z))
        .collect();
    engine.set_positions(&moved).unwrap();
    let starts: Vec<_> = before.iter().map(|c| c.patch).collect();
    let local = engine.closest_points_local(&queries, &starts).unwrap();
    let full = engine.closest_points(&queries).unwrap();
    let fresh = ClosestPointEngine::new(&r, &moved, &ClosestPointParams::default())
        .unwrap()
        .closest_points(&queries)
        .unwrap();
    // A looser Newton tolerance (what fitting uses) gives the same distances.
    let loose = ClosestPointEngine::new(
        &r,
        &moved,
        &ClosestPointParams {
            tolerance: 1e-7,
            ..Default::default()
        },
    )
    .unwrap()
    .closest_points(&queries)
    .unwrap();
    let zero = ClosestPointParams {
        tolerance: 0.0,
        ..Default::default()
    };
    assert!(ClosestPointEngine::new(&r, &moved, &zero).is_err());
    let d = diag(&moved);
    for (l, g) in loose.iter().zip(&fresh) {
        assert!(
            (l.distance - g.distance).abs() <= 1e-13 * d,
            "tolerance 1e-7: {} vs {}",
            l.distance,
            g.distance
        );
    }
    for ((l, f), g) in local.iter().zip(&full).zip(&fresh) {
        assert!(
            (l.distance - f.distance).abs() <= 1e-12 * d,
            "local {} vs full {}",
            l.distance,
            f.distance
        );
        assert!(
            (f.distance - g.distance).abs() <= 1e-14 * d,
            "moved {} vs fresh {}",
            f.distance,
            g.distance
        );
    }
}

/// Patch `f` of a level-1 table is base face `f` of the once-refined mesh,
/// in the same `(s, t)` frame (the fit carries its closest points from one
/// level to the next this way): `locate` on the refined mesh's table finds
/// the same limit point, on meshes with irregular vertices, boundaries and
/// n-gons.
#[test]
fn level_one_patches_are_the_refined_meshs_faces() {
    let mut rng = Rng::new(5);
    for mesh in [mixed_mesh(), pentagonal_pyramid(), subdyn::examples::cube()] {
        let r = default_refiner(&mesh);
        let coarse = PatchTable::new(&r, &mesh.positions, 1).unwrap();
        let h = r.refine_uniform(1).unwrap();
        let fine_mesh = h.mesh(1, h.stencil(0).apply(&mesh.positions).unwrap());
        let fine = PatchTable::new(&default_refiner(&fine_mesh), &fine_mesh.positions, 1).unwrap();
        assert_eq!(coarse.num_patches(), fine_mesh.num_faces());
        let scale = diag(&mesh.positions);
        for f in 0..coarse.num_patches() {
            let st = [rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)];
            let a = coarse.eval(f, st).unwrap().p;
            let (g, gst) = fine.locate(f, st[0], st[1]);
            let b = fine.eval(g, gst).unwrap().p;
            assert!(
                (a - b).norm() <= 1e-12 * scale,
                "patch {f} at {st:?}: {a} vs {b}"
            );
        }
    }
}

/// A hint on the wrong side of the surface does not trap the search: the
/// nearest seed is closer than where the descent from the hint ends, so it
/// is descended from too, and the answer is the unhinted one. A hint at the
/// answer itself gives the same answer, and an out-of-range hint counts as
/// none.
#[test]
fn closest_point_near_recovers_from_a_hint_on_the_far_side() {
    let mesh = subdyn::examples::cube();
    let r = default_refiner(&mesh);
    let engine =
        ClosestPointEngine::new(&r, &mesh.positions, &ClosestPointParams::default()).unwrap();
    let centre = Point3::from(
        mesh.positions.iter().map(|p| p.coords).sum::<Vector3>() / mesh.positions.len() as f64,
    );
    let mut rng = Rng::new(7);
    let queries: Vec<Point3> = (0..50)
        .map(|_| {
            let d = Vector3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            );
            centre + 3.0 * d.normalize()
        })
        .collect();
    let plain = engine.closest_points(&queries).unwrap();
    // The far side: the answer of the query mirrored through the centre.
    let mirrored: Vec<Point3> = queries.iter().map(|q| centre - (q - centre)).collect();
    let far: Vec<(u32, [f64; 2])> = engine
        .closest_points(&mirrored)
        .unwrap()
        .iter()
        .map(|c| c.patch)
        .collect();
    let own: Vec<(u32, [f64; 2])> = plain.iter().map(|c| c.patch).collect();
    let out_of_range = vec![(u32::MAX, [0.5, 0.5]); queries.len()];
    for hints in [&far, &own, &out_of_range] {
        let hinted = engine.closest_points_near(&queries, hints).unwrap();
        for ((q, a), b) in queries.iter().zip(&plain).zip(&hinted) {
            assert!(
                (a.distance - b.distance).abs() < 1e-9 && (a.point - b.point).norm() < 1e-6,
                "{q}: unhinted {} at {}, hinted {} at {}",
                a.distance,
                a.point,
                b.distance,
                b.point
            );
        }
    }
}

/// Patch tables sharing one quadtree cache (as the levels of a fit do)
/// evaluate exactly as tables with their own: a structure's leaves depend
/// on nothing but the structure.
#[test]
fn shared_quadtree_cache_changes_no_evaluation() {
    let shared = subdyn::limit::QuadtreeCache::default();
    for (mesh, name) in [
        (pentagonal_pyramid(), "pentagonal pyramid"),
        (mixed_mesh(), "mixed mesh"),
        (subdyn::examples::cube(), "cube"),
    ] {
        let r = default_refiner(&mesh);
        let own = PatchTable::new(&r, &mesh.positions, 1).unwrap();
        let with_shared =
            PatchTable::with_quadtrees(&r, &mesh.positions, 1, shared.clone()).unwrap();
        for f in 0..own.num_patches() {
            for st in [[0.5, 0.5], [0.1, 0.7], [0.004, 0.002], [0.3, 0.0]] {
                let (a, b) = (own.eval(f, st).unwrap(), with_shared.eval(f, st).unwrap());
                assert!(
                    a.p == b.p && a.d == b.d,
                    "{name}: patch {f} at {st:?}: {:?} against {:?}",
                    a,
                    b
                );
            }
        }
    }
    assert!(format!("{shared:?}").contains("structures"));
}

/// `PatchTable::position` is `eval`'s point, on regular patches, quadtree
/// leaves and the innermost cells at irregular vertices (within 1/64 of the
/// corner, evaluated from the cell's local patch); there the point is the
/// limit evaluator's and the first derivatives match central differences.
#[test]
fn patch_position_equals_the_evaluated_point() {
    for (mesh, name) in [
        (pentagonal_pyramid(), "pentagonal pyramid"),
        (mixed_mesh(), "mixed mesh"),
        (subdyn::examples::cube(), "cube"),
    ] {
        let d = diag(&mesh.positions);
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 1).unwrap();
        let eval = LimitEvaluator::new(&r);
        for f in 0..table.num_patches() {
            for st in [
                [0.5, 0.5],
                [0.1, 0.7],
                [0.004, 0.002],
                [0.3, 0.0],
                [1.0, 1.0],
            ] {
                let (p, e) = (table.position(f, st).unwrap(), table.eval(f, st).unwrap());
                assert!(
                    (p - e.p).norm() <= 1e-14 * d,
                    "{name}: patch {f} at {st:?}: {p} against {}",
                    e.p
                );
            }
            for st in [[0.004, 0.002], [0.002, 0.01], [0.996, 0.999], [0.0, 0.0]] {
                let differences = st != [0.0, 0.0];
                check_eval_at(&table, &eval, &mesh.positions, f, st, differences, name);
            }
        }
    }
}

/// `table.eval(f, st)` is the exact evaluator's point to 1e-12 of the
/// diagonal and, with `differences`, its first derivatives match central
/// differences of `table.position`.
fn check_eval_at(
    table: &PatchTable,
    eval: &LimitEvaluator,
    positions: &[Point3],
    f: usize,
    st: [f64; 2],
    differences: bool,
    name: &str,
) {
    let d = diag(positions);
    let e = table.eval(f, st).unwrap();
    let s = table.sample(f, st);
    let exact = eval.evaluate(s.face as usize, s.u, s.v, positions).unwrap();
    assert!(
        (e.p - exact.p).norm() <= 1e-12 * d,
        "{name}: patch {f} at {st:?}: {} against the evaluator's {}",
        e.p,
        exact.p
    );
    if !differences {
        return;
    }
    let h = 1e-7;
    for (k, step) in [[h, 0.0], [0.0, h]].iter().enumerate() {
        let at = |sign: f64| {
            let q = [st[0] + sign * step[0], st[1] + sign * step[1]];
            table.position(f, q).unwrap()
        };
        let fd = (at(1.0) - at(-1.0)) / (2.0 * h);
        assert!(
            (fd - e.d[k]).norm() <= 1e-5 * e.d[k].norm().max(d),
            "{name}: patch {f} at {st:?}: derivative {k} {} against {fd}",
            e.d[k]
        );
    }
}

/// Near a vertex of high valence (a fan of 40 and of 100 quads, wavy so
/// that nothing is planar) `eval` follows the innermost cell towards the
/// vertex once and reuses it: its points still equal the exact
/// evaluator's, from 1/256 of the corner down to 1e-13 of it, and its
/// first derivatives match central differences.
#[test]
fn evaluation_near_a_vertex_of_high_valence_is_exact() {
    for n in [40usize, 100] {
        let mut p = vec![Point3::new(0.0, 0.0, 0.3)];
        for i in 0..n {
            let (a, b) = (TAU * i as f64 / n as f64, TAU * (i as f64 + 0.5) / n as f64);
            p.push(Point3::new(a.cos(), a.sin(), 0.1 * (3.0 * a).sin()));
            p.push(Point3::new(
                1.5 * b.cos(),
                1.5 * b.sin(),
                0.1 * (5.0 * b).cos(),
            ));
        }
        let faces: Vec<Vec<u32>> = (0..n as u32)
            .map(|i| vec![0, 1 + 2 * i, 2 + 2 * i, 1 + 2 * ((i + 1) % n as u32)])
            .collect();
        let fan = PolyMesh::from_faces(p, &faces).unwrap();
        let r = default_refiner(&fan);
        let table = PatchTable::new(&r, &fan.positions, 1).unwrap();
        let eval = LimitEvaluator::new(&r);
        let mut checked = 0;
        for f in 0..table.num_patches() {
            // Only the patches whose corner (0, 0) is the fan's centre
            // (every face lists it first).
            let s = table.sample(f, [0.0, 0.0]);
            if (s.u, s.v) != (0.0, 0.0) {
                continue;
            }
            for st in [
                [0.004, 0.002],
                [0.002, 0.003],
                [3e-6, 1e-6],
                [1e-9, 2e-9],
                [1e-13, 0.0],
            ] {
                let name = format!("valence {n}");
                check_eval_at(&table, &eval, &fan.positions, f, st, st[0] >= 1e-3, &name);
            }
            checked += 1;
        }
        assert_eq!(
            checked, n,
            "valence {n}: one patch per fan face at the centre"
        );
    }
}

/// Quadtree structures are keyed by the topology around a face, not by how
/// the mesh numbers its faces: the same meshes with their faces listed in
/// reverse order, each face's corners rotated by one, need exactly as many
/// structures, and every table evaluates the exact limit surface
/// ([`LimitEvaluator`]) at random points of every patch.
#[test]
fn quadtree_structures_do_not_depend_on_face_numbering() {
    let mut rng = Rng::new(11);
    for (mesh, name) in [
        (pentagonal_pyramid(), "pentagonal pyramid"),
        (mixed_mesh(), "mixed mesh"),
        (subdyn::examples::cube(), "cube"),
        (refined_cube(), "cube refined twice"),
    ] {
        let faces: Vec<Vec<u32>> = (0..mesh.num_faces())
            .rev()
            .map(|f| {
                let mut c = mesh.face(f).to_vec();
                c.rotate_left(1);
                c
            })
            .collect();
        let relisted = PolyMesh::from_faces(mesh.positions.clone(), &faces).unwrap();
        let mut counts = Vec::new();
        for m in [&mesh, &relisted] {
            let cache = subdyn::limit::QuadtreeCache::default();
            let r = default_refiner(m);
            let table = PatchTable::with_quadtrees(&r, &m.positions, 1, cache.clone()).unwrap();
            let exact = LimitEvaluator::new(&r);
            let scale = diag(&m.positions);
            for f in 0..table.num_patches() {
                let st = [rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)];
                let a = table.eval(f, st).unwrap().p;
                let s = table.sample(f, st);
                let b = exact
                    .evaluate(s.face as usize, s.u, s.v, &m.positions)
                    .unwrap()
                    .p;
                assert!(
                    (a - b).norm() <= 1e-12 * scale,
                    "{name}: patch {f} at {st:?}: {a} against {b}"
                );
            }
            counts.push(format!("{cache:?}"));
        }
        assert_eq!(counts[0], counts[1], "{name}");
    }
}

/// The cube refined twice: 96 quads, its 8 valence-3 corners far apart.
fn refined_cube() -> PolyMesh {
    let cube = subdyn::examples::cube();
    let h = default_refiner(&cube).refine_uniform(2).unwrap();
    let p = h
        .stencil_to_level(2)
        .unwrap()
        .apply(&cube.positions)
        .unwrap();
    h.mesh(2, p)
}

//! Integration tests of Catmull-Clark refinement (`subdyn::subdivision`,
//! `subdyn::stencil`): agreement with OpenSubdiv 3.6 on the reference meshes,
//! and invariants on tiny hand-built meshes — stencil rows sum to one,
//! affine invariance, bicubic B-spline reproduction on a regular grid, level
//! composition, Catmull-Clark counts, crease and boundary rules.
//!
//! Fixtures: `tests/data/opensubdiv/` (OpenSubdiv 3.6 references, see its
//! README) and the meshes built in `tests/common/mod.rs`.

mod common;

use common::*;
use subdyn::limit::{cubic_basis, limit_stencil};
use subdyn::math::Point3;
use subdyn::mesh::PolyMesh;
use subdyn::stencil::StencilTable;
use subdyn::subdivision::{BoundaryRule, Hierarchy};
use subdyn::topology::{Level, SHARPNESS_INFINITE};

/// Agreement with OpenSubdiv, relative to the bounding-box diagonal.
const OSD_TOL: f64 = 1e-9;
/// Round-off allowed in a stencil row sum.
const ROW_SUM_TOL: f64 = 1e-12;
/// Round-off allowed between two exact computations of the same points,
/// relative to the bounding-box diagonal.
const EXACT_TOL: f64 = 1e-12;

const BOTH_RULES: [BoundaryRule; 2] = [BoundaryRule::EdgeAndCorner, BoundaryRule::EdgeOnly];

// ---------------------------------------------------------------------------
// OpenSubdiv agreement

/// Level-3 points and their limit positions against `NAME.L3.obj` and
/// `NAME.limit.xyz`; returns the largest errors relative to the diagonal.
fn check_opensubdiv(name: &str) -> (f64, f64) {
    let mesh = reference_mesh(name);
    let d = diag(&mesh.positions);
    let h = default_refiner(&mesh).refine_uniform(3).unwrap();
    let p3 = h
        .stencil_to_level(3)
        .unwrap()
        .apply(&mesh.positions)
        .unwrap();
    let reference = subdyn::io::read_mesh(opensubdiv(&format!("{name}.L3.obj"))).unwrap();
    assert_eq!(
        p3.len(),
        reference.num_vertices(),
        "{name}: level-3 vertex count"
    );
    assert_eq!(
        h.level(3).num_faces(),
        reference.num_faces(),
        "{name}: level-3 face count"
    );
    let err_l3 = point_set_distance(&p3, &reference.positions) / d;

    let limit = limit_stencil(&h, 3)
        .unwrap()
        .apply(&mesh.positions)
        .unwrap();
    let reference_limit = read_xyz(&opensubdiv(&format!("{name}.limit.xyz")));
    assert_eq!(
        limit.len(),
        reference_limit.len(),
        "{name}: limit point count"
    );
    let err_limit = point_set_distance(&limit, &reference_limit) / d;
    println!("{name}: level 3 max error {err_l3:.3e}·diag, limit {err_limit:.3e}·diag");
    assert!(
        err_l3 <= OSD_TOL,
        "{name}: level-3 points differ from OpenSubdiv by {err_l3:e}·diag (> {OSD_TOL:e})"
    );
    assert!(
        err_limit <= OSD_TOL,
        "{name}: level-3 limit positions differ from OpenSubdiv by {err_limit:e}·diag (> {OSD_TOL:e})"
    );
    // Same faces (as oriented vertex cycles) once our vertices are matched
    // to OpenSubdiv's by position.
    let to_osd: Vec<usize> = p3
        .iter()
        .map(|p| {
            (0..reference.num_vertices())
                .min_by(|&a, &b| {
                    let (da, db) = (reference.positions[a] - p, reference.positions[b] - p);
                    da.norm_squared().total_cmp(&db.norm_squared())
                })
                .unwrap()
        })
        .collect();
    let canonical = |f: Vec<usize>| {
        let k = (0..f.len()).min_by_key(|&i| f[i]).unwrap();
        (0..f.len())
            .map(|i| f[(k + i) % f.len()])
            .collect::<Vec<_>>()
    };
    let mut ours: Vec<Vec<usize>> = (0..h.level(3).num_faces())
        .map(|f| {
            canonical(
                h.level(3)
                    .face_vertices(f)
                    .iter()
                    .map(|&v| to_osd[v as usize])
                    .collect(),
            )
        })
        .collect();
    let mut theirs: Vec<Vec<usize>> = reference
        .faces()
        .map(|f| canonical(f.iter().map(|&v| v as usize).collect()))
        .collect();
    ours.sort();
    theirs.sort();
    assert!(
        ours == theirs,
        "{name}: level-3 faces differ from OpenSubdiv's"
    );
    (err_l3, err_limit)
}

#[test]
fn cube_level3_and_limit_match_opensubdiv() {
    check_opensubdiv("cube");
}

#[test]
fn fan5_open_level3_and_limit_match_opensubdiv() {
    check_opensubdiv("fan5_open");
}

#[test]
fn grid4_open_level3_and_limit_match_opensubdiv() {
    check_opensubdiv("grid4_open");
}

#[test]
fn torus_regular_level3_and_limit_match_opensubdiv() {
    check_opensubdiv("torus_regular");
}

// ---------------------------------------------------------------------------
// Stencil invariants

fn assert_rows_sum_to_one(t: &StencilTable, what: &str) {
    for (r, s) in t.row_sums().iter().enumerate() {
        assert!(
            (s - 1.0).abs() <= ROW_SUM_TOL,
            "{what}: row {r} sums to {s}"
        );
    }
}

#[test]
fn stencil_rows_sum_to_one_on_mixed_creased_mesh() {
    let mesh = mixed_mesh();
    for rule in BOTH_RULES {
        for creases in [vec![], mixed_creases()] {
            let h = refiner(&mesh, rule, &creases).refine_uniform(3).unwrap();
            for k in 0..3 {
                let s = &h.stencils[k];
                assert_eq!(
                    s.num_rows(),
                    h.level(k + 1).num_vertices,
                    "{rule:?}: rows of S_{k}"
                );
                assert_eq!(
                    s.num_cols,
                    h.level(k).num_vertices,
                    "{rule:?}: columns of S_{k}"
                );
                assert_rows_sum_to_one(s, &format!("{rule:?}, {} creases, S_{k}", creases.len()));
            }
            let s = h.stencil_to_level(3).unwrap();
            assert_rows_sum_to_one(
                &s,
                &format!("{rule:?}, {} creases, composed S", creases.len()),
            );
        }
    }
}

#[test]
fn refinement_commutes_with_affine_maps() {
    let mesh = mixed_mesh();
    let mut rng = Rng::new(7);
    for rule in BOTH_RULES {
        let r = refiner(&mesh, rule, &mixed_creases());
        let h = r.refine_uniform(3).unwrap();
        let s = h.stencil_to_level(3).unwrap();
        let (a, b) = random_affine(&mut rng);
        let moved = affine(&mesh.positions, &a, &b);
        let lhs = s.apply(&moved).unwrap();
        let rhs = affine(&s.apply(&mesh.positions).unwrap(), &a, &b);
        let err = max_pairwise(&lhs, &rhs) / diag(&moved);
        assert!(
            err <= EXACT_TOL,
            "{rule:?}: refine(Ap + b) − (A refine(p) + b) = {err:e}·diag"
        );
        // Level by level too.
        let levels = h.refine_positions(&moved).unwrap();
        let err = max_pairwise(&levels[3], &rhs) / diag(&moved);
        assert!(
            err <= EXACT_TOL,
            "{rule:?}: level-by-level affine error {err:e}·diag"
        );
    }
}

#[test]
fn composed_stencil_equals_level_by_level_refinement() {
    let mesh = mixed_mesh();
    let d = diag(&mesh.positions);
    for rule in BOTH_RULES {
        let h = refiner(&mesh, rule, &mixed_creases())
            .refine_uniform(3)
            .unwrap();
        let levels = h.refine_positions(&mesh.positions).unwrap();
        assert_eq!(levels.len(), 4);
        for (k, stepwise) in levels.iter().enumerate() {
            let composed = h
                .stencil_to_level(k)
                .unwrap()
                .apply(&mesh.positions)
                .unwrap();
            assert_eq!(composed.len(), h.level(k).num_vertices);
            let err = max_pairwise(&composed, stepwise) / d;
            assert!(
                err <= EXACT_TOL,
                "{rule:?}: level {k}: composed vs step-wise differ by {err:e}·diag"
            );
        }
        // By hand: S_1 S_0.
        let by_hand = h.stencils[1].compose(&h.stencils[0]).unwrap();
        let err = max_pairwise(&by_hand.apply(&mesh.positions).unwrap(), &levels[2]) / d;
        assert!(
            err <= EXACT_TOL,
            "{rule:?}: S_1·S_0 differs by {err:e}·diag"
        );
    }
    let h = default_refiner(&subdyn::examples::cube())
        .refine_uniform(1)
        .unwrap();
    assert!(
        h.stencil_to_level(2).is_err(),
        "level 2 of a one-level hierarchy must be an error"
    );
}

// ---------------------------------------------------------------------------
// Regular grids reproduce the uniform bicubic B-spline

/// Number of vertices per side of the test grid.
const GRID_N: usize = 10;

/// The uniform bicubic B-spline of a grid of control points `cp(i, j)`
/// (`0 ≤ i, j < n`) at parameter `(x, y)` in control-point units.
fn bspline(cp: impl Fn(usize, usize) -> Point3, n: usize, x: f64, y: f64) -> Point3 {
    let span = |x: f64| -> (usize, f64) {
        let i = (x.floor() as usize).min(n - 3);
        assert!(
            i >= 1 && x - i as f64 <= 1.0 + 1e-12,
            "parameter {x} outside the spline's domain"
        );
        (i, x - i as f64)
    };
    let ((i, s), (j, t)) = (span(x), span(y));
    let (bs, bt) = (cubic_basis(s)[0], cubic_basis(t)[0]);
    let mut out = nalgebra::Vector3::zeros();
    for (a, wa) in bs.iter().enumerate() {
        for (b, wb) in bt.iter().enumerate() {
            out += wa * wb * cp(i - 1 + a, j - 1 + b).coords;
        }
    }
    Point3::from(out)
}

/// Level-`k` vertices whose stencil row involves no boundary vertex of the
/// grid, with their parameters: all Catmull-Clark weights on a regular grid
/// are positive, so such a row was made by interior (B-spline) rules only,
/// and applying it to the parameter grid `(i, j)` gives its parameter.
fn interior_rows(s: &StencilTable, n: usize) -> Vec<(usize, f64, f64)> {
    let on_boundary = |c: u32| {
        let (i, j) = (c as usize / n, c as usize % n);
        i == 0 || j == 0 || i == n - 1 || j == n - 1
    };
    (0..s.num_rows())
        .filter_map(|r| {
            let (cols, w) = s.row(r);
            if cols.iter().any(|&c| on_boundary(c)) {
                return None;
            }
            assert!(
                w.iter().all(|&w| w > 0.0),
                "regular-grid stencil row {r} has a non-positive weight"
            );
            let x: f64 = cols
                .iter()
                .zip(w)
                .map(|(&c, &w)| w * (c as usize / n) as f64)
                .sum();
            let y: f64 = cols
                .iter()
                .zip(w)
                .map(|(&c, &w)| w * (c as usize % n) as f64)
                .sum();
            Some((r, x, y))
        })
        .collect()
}

#[test]
fn cubic_basis_is_the_uniform_b_spline_basis() {
    for &t in &[0.0, 0.3, 0.71, 1.0] {
        let s: f64 = 1.0 - t;
        let expect = [
            s.powi(3) / 6.0,
            (3.0 * t.powi(3) - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t.powi(3) / 6.0,
        ];
        for (a, b) in cubic_basis(t)[0].iter().zip(expect) {
            assert!((a - b).abs() < 1e-15, "B({t}) = {a}, expected {b}");
        }
    }
}

#[test]
fn regular_grid_refinement_reproduces_bicubic_b_spline() {
    let n = GRID_N;
    let levels = 3;
    let scale = (1 << levels) as f64;
    let mesh = grid(n, 11);
    let d = diag(&mesh.positions);
    let p0 = &mesh.positions;
    let cp0 = |i: usize, j: usize| p0[grid_id(n, i, j) as usize];
    let h = default_refiner(&mesh).refine_uniform(levels).unwrap();
    let s = h.stencil_to_level(levels).unwrap();
    let pk = s.apply(p0).unwrap();

    // Refined control points: parameters are dyadic, and the level-k grid
    // spans the same spline: B-spline(P_k)(2^k x) = B-spline(P_0)(x).
    let rows = interior_rows(&s, n);
    assert!(rows.len() > 200, "only {} interior rows", rows.len());
    let mut at = std::collections::HashMap::new();
    for &(r, x, y) in &rows {
        let (a, b) = (x * scale, y * scale);
        assert!(
            (a - a.round()).abs() < 1e-9 && (b - b.round()).abs() < 1e-9,
            "vertex {r}: parameter ({x}, {y}) is not a multiple of 2^-{levels}"
        );
        assert!(
            at.insert((a.round() as i64, b.round() as i64), r).is_none(),
            "two vertices at ({x}, {y})"
        );
    }
    let mut rng = Rng::new(3);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for &(a, b) in at.keys() {
        let cells: Option<Vec<usize>> = (0..16)
            .map(|k| {
                at.get(&(a - 1 + (k / 4) as i64, b - 1 + (k % 4) as i64))
                    .copied()
            })
            .collect();
        let Some(cells) = cells else { continue };
        let (s, t) = (rng.next_f64(), rng.next_f64());
        let fine = bspline(|i, j| pk[cells[4 * i + j]], 4, 1.0 + s, 1.0 + t);
        let coarse = bspline(cp0, n, (a as f64 + s) / scale, (b as f64 + t) / scale);
        worst = worst.max((fine - coarse).norm() / d);
        checked += 1;
    }
    assert!(checked > 100, "only {checked} level-{levels} cells checked");
    assert!(
        worst <= EXACT_TOL,
        "refined grid's spline differs from the original by {worst:e}·diag"
    );

    // Limit positions of level-k vertices lie on the spline at their parameters.
    let lim = limit_stencil(&h, levels).unwrap();
    let lp = lim.apply(p0).unwrap();
    let lrows = interior_rows(&lim, n);
    assert!(
        lrows.len() > 100,
        "only {} interior limit rows",
        lrows.len()
    );
    let worst = lrows
        .iter()
        .map(|&(r, x, y)| (lp[r] - bspline(cp0, n, x, y)).norm() / d)
        .fold(0.0, f64::max);
    assert!(
        worst <= EXACT_TOL,
        "limit positions differ from the B-spline by {worst:e}·diag"
    );
}

// ---------------------------------------------------------------------------
// Counts

/// Checks V' = V + E + F, F' = Σ|f|, E' = 2E + Σ|f|, all-quad children, and
/// that the refined connectivity agrees with one rebuilt from its faces.
fn check_counts(mesh: &PolyMesh, name: &str) {
    let h = default_refiner(mesh).refine_uniform(3).unwrap();
    for k in 0..3 {
        let (p, c) = (h.level(k), h.level(k + 1));
        let corners: usize = (0..p.num_faces()).map(|f| p.face_vertices(f).len()).sum();
        assert_eq!(
            c.num_vertices,
            p.num_vertices + p.num_edges() + p.num_faces(),
            "{name}: V{}",
            k + 1
        );
        assert_eq!(c.num_faces(), corners, "{name}: F{}", k + 1);
        assert_eq!(
            c.num_edges(),
            2 * p.num_edges() + corners,
            "{name}: E{}",
            k + 1
        );
        for f in 0..c.num_faces() {
            assert_eq!(
                c.face_vertices(f).len(),
                4,
                "{name}: level {} face {f} is not a quad",
                k + 1
            );
        }
        let rebuilt = Level::from_mesh(&h.mesh(k + 1, vec![Point3::origin(); c.num_vertices]))
            .unwrap_or_else(|e| panic!("{name}: level {} is not a valid mesh: {e}", k + 1));
        assert_eq!(
            rebuilt.num_edges(),
            c.num_edges(),
            "{name}: level {} edges",
            k + 1
        );
        let boundary = |l: &Level| {
            (0..l.num_edges())
                .filter(|&e| l.is_boundary_edge(e))
                .count()
        };
        assert_eq!(
            boundary(&rebuilt),
            boundary(c),
            "{name}: level {} boundary edges",
            k + 1
        );
        assert_eq!(
            boundary(c),
            2 * boundary(p),
            "{name}: level {} boundary edges double",
            k + 1
        );
    }
}

#[test]
fn pentagon_and_triangle_meshes_become_quads_with_catmull_clark_counts() {
    let pyramid = pentagonal_pyramid();
    let h = default_refiner(&pyramid).refine_uniform(1).unwrap();
    // 6 vertices, 10 edges, 6 faces (5 + 5·3 = 20 corners).
    assert_eq!(h.level(1).num_vertices, 6 + 10 + 6);
    assert_eq!(h.level(1).num_faces(), 20);
    assert_eq!(h.level(1).num_edges(), 2 * 10 + 20);
    check_counts(&pyramid, "pentagonal pyramid");
    check_counts(&mixed_mesh(), "mixed mesh");
    check_counts(&triangular_prism(), "prism");
}

// ---------------------------------------------------------------------------
// Creases

/// The loop of cube face 1 (x = 1), in its face order.
const LOOP: [u32; 4] = [4, 6, 7, 5];

fn loop_creases(s: f64) -> Vec<(u32, u32, f64)> {
    (0..4).map(|i| (LOOP[i], LOOP[(i + 1) % 4], s)).collect()
}

/// One step of closed cubic B-spline curve subdivision: vertex points
/// `(a + 6v + b)/8`, edge points `(v + w)/2`.
fn curve_subdivide(p: &[Point3]) -> Vec<Point3> {
    let n = p.len();
    let mut out = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (a, v, b) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
        out.push(Point3::from((a.coords + 6.0 * v.coords + b.coords) / 8.0));
        out.push(Point3::from((v.coords + b.coords) / 2.0));
    }
    out
}

/// The closed uniform cubic B-spline of `p` at `t` (one unit per control point).
fn closed_curve(p: &[Point3], t: f64) -> Point3 {
    let n = p.len();
    let i = t.floor();
    let b = cubic_basis(t - i)[0];
    let i = i as i64;
    let mut out = nalgebra::Vector3::zeros();
    for (a, w) in b.iter().enumerate() {
        out += *w * p[(i - 1 + a as i64).rem_euclid(n as i64) as usize].coords;
    }
    Point3::from(out)
}

/// Vertices of level `k` on an infinitely sharp (non-boundary) edge.
fn crease_vertices(h: &Hierarchy, k: usize) -> Vec<usize> {
    let l = h.level(k);
    let mut out: Vec<usize> = (0..l.num_edges())
        .filter(|&e| h.sharpness[k].edge[e] >= SHARPNESS_INFINITE && !l.is_boundary_edge(e))
        .flat_map(|e| l.edge_verts[e].map(|v| v as usize))
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

#[test]
fn infinitely_sharp_crease_loop_follows_the_cubic_b_spline_curve() {
    let cube = perturbed(subdyn::examples::cube(), 0.1, 5);
    let d = diag(&cube.positions);
    let r = refiner(&cube, BoundaryRule::EdgeAndCorner, &loop_creases(INFINITE));
    let h = r.refine_uniform(3).unwrap();
    let ctrl: Vec<Point3> = LOOP.iter().map(|&v| cube.positions[v as usize]).collect();

    // Refined points along the crease: three steps of the (1, 6, 1)/8 curve rule.
    let on = crease_vertices(&h, 3);
    assert_eq!(on.len(), 32, "level 3 should have 4·8 crease vertices");
    let p3 = h
        .stencil_to_level(3)
        .unwrap()
        .apply(&cube.positions)
        .unwrap();
    let got: Vec<Point3> = on.iter().map(|&v| p3[v]).collect();
    let expect = curve_subdivide(&curve_subdivide(&curve_subdivide(&ctrl)));
    let err = point_set_distance(&got, &expect) / d;
    assert!(
        err <= EXACT_TOL,
        "level-3 crease points are off the curve rule by {err:e}·diag"
    );

    // Their limit positions lie on the B-spline curve at parameters j/8.
    let lp = limit_stencil(&h, 3)
        .unwrap()
        .apply(&cube.positions)
        .unwrap();
    let got: Vec<Point3> = on.iter().map(|&v| lp[v]).collect();
    let expect: Vec<Point3> = (0..32)
        .map(|j| closed_curve(&ctrl, j as f64 / 8.0))
        .collect();
    let err = point_set_distance(&got, &expect) / d;
    assert!(
        err <= EXACT_TOL,
        "crease limit positions are off the B-spline by {err:e}·diag"
    );

    // The limit surface on both sides of the crease follows the curve too.
    let eval = subdyn::limit::LimitEvaluator::new(&r);
    let mut worst: f64 = 0.0;
    for f in 0..cube.num_faces() {
        let fv = cube.face(f);
        for k in 0..4 {
            let (a, b) = (fv[k], fv[(k + 1) % 4]);
            let (Some(ia), Some(ib)) = (
                LOOP.iter().position(|&x| x == a),
                LOOP.iter().position(|&x| x == b),
            ) else {
                continue;
            };
            for tau in [0.0, 0.2, 0.5, 0.9] {
                let ((u, v), _) = edge_param(4, k, tau);
                let p = eval.evaluate(f, u, v, &cube.positions).unwrap().p;
                let t = if ib == (ia + 1) % 4 {
                    ia as f64 + tau
                } else {
                    ia as f64 - tau
                };
                worst = worst.max((p - closed_curve(&ctrl, t.rem_euclid(4.0))).norm() / d);
            }
        }
    }
    assert!(
        worst <= EXACT_TOL,
        "limit surface along the crease is off the curve by {worst:e}·diag"
    );
}

#[test]
fn semi_sharp_crease_lies_between_smooth_and_sharp() {
    let cube = subdyn::examples::cube();
    let p = &cube.positions;
    let sharpness = [0.0, 0.5, 1.0, 1.5, 2.0, 3.0, INFINITE];
    let (v, w) = (LOOP[0] as usize, LOOP[1] as usize);
    let mid = Point3::from((p[v].coords + p[w].coords) / 2.0);
    let mut edge_d = Vec::new();
    let mut vertex_d = Vec::new();
    let mut refined_d = Vec::new();
    let mut level3 = Vec::new();
    for &s in &sharpness {
        let creases = if s > 0.0 { loop_creases(s) } else { vec![] };
        let r = refiner(&cube, BoundaryRule::EdgeAndCorner, &creases);
        let h = r.refine_uniform(3).unwrap();
        // Limit at the middle of crease edge (4, 6): face 1 = [4 6 7 5], edge 0.
        let eval = subdyn::limit::LimitEvaluator::new(&r);
        let lm = eval.evaluate(1, 0.5, 0.0, p).unwrap().p;
        edge_d.push((lm - mid).norm());
        let lv = limit_stencil(&h, 0).unwrap().apply(p).unwrap()[v];
        vertex_d.push((lv - p[v]).norm());
        let p3 = h.stencil_to_level(3).unwrap().apply(p).unwrap();
        refined_d.push((p3[descendant(&h, 3, v)] - p[v]).norm());
        level3.push(p3);
    }
    println!(
        "sharpness {sharpness:?}\n  edge-midpoint limit distance {edge_d:?}\n  vertex limit distance {vertex_d:?}"
    );
    for i in 1..sharpness.len() {
        let (a, b) = (sharpness[i - 1], sharpness[i]);
        assert!(
            edge_d[i] < edge_d[i - 1],
            "edge limit distance not decreasing from s={a} to s={b}: {edge_d:?}"
        );
        assert!(
            vertex_d[i] < vertex_d[i - 1],
            "vertex limit distance not decreasing from s={a} to s={b}: {vertex_d:?}"
        );
    }
    // Up to level 3 a crease of sharpness ≥ 3 cannot be told from an infinite one;
    // below that the refined vertex moves monotonically towards its control point.
    for i in 1..5 {
        assert!(
            refined_d[i] < refined_d[i - 1],
            "level-3 vertex distance not decreasing at s={}: {refined_d:?}",
            sharpness[i]
        );
    }
    let err = max_pairwise(&level3[5], &level3[6]);
    assert!(
        err <= EXACT_TOL,
        "level 3 with s=3 differs from s=∞ by {err:e}"
    );
    let err = max_pairwise(&level3[4], &level3[5]);
    assert!(
        err > 1e-6,
        "level 3 with s=2 equals s=3: the sharpness decrement is not applied"
    );
}

/// Level-1 points of the cube with the loop of face 1 at sharpness 0.5 and
/// 1.5, against the rules written out by hand (DeRose et al. 1998 with
/// OpenSubdiv's fractional blending): a sharpness-0.5 edge point is half the
/// midpoint plus half the smooth edge point; a vertex whose two crease edges
/// decay to 0 blends the crease and smooth vertex rules by the mean sharpness.
#[test]
fn semi_sharp_rules_blend_by_fractional_sharpness() {
    let cube = perturbed(subdyn::examples::cube(), 0.1, 8);
    let p: Vec<nalgebra::Vector3<f64>> = cube.positions.iter().map(|x| x.coords).collect();
    let d = diag(&cube.positions);
    let centroid = |f: usize| {
        cube.face(f)
            .iter()
            .map(|&v| p[v as usize])
            .sum::<nalgebra::Vector3<f64>>()
            / 4.0
    };
    // Edge (4, 6) lies in faces 1 = [4 6 7 5] and 4 = [0 2 6 4]; vertex 4 has
    // neighbours 6, 5 (on the loop) and 0, and faces 1, 2, 4.
    let mid = (p[4] + p[6]) / 2.0;
    let smooth_edge = (p[4] + p[6] + centroid(1) + centroid(4)) / 4.0;
    let crease_vertex = (p[6] + 6.0 * p[4] + p[5]) / 8.0;
    let smooth_vertex =
        p[4] / 3.0 + (p[6] + p[5] + p[0]) / 9.0 + (centroid(1) + centroid(2) + centroid(4)) / 9.0;
    for (s, edge, vertex) in [
        (
            0.5,
            0.5 * mid + 0.5 * smooth_edge,
            0.5 * crease_vertex + 0.5 * smooth_vertex,
        ),
        (1.5, mid, crease_vertex),
    ] {
        let r = refiner(&cube, BoundaryRule::EdgeAndCorner, &loop_creases(s));
        let h = r.refine_uniform(1).unwrap();
        let p1 = h
            .stencil_to_level(1)
            .unwrap()
            .apply(&cube.positions)
            .unwrap();
        let e = subdyn::topology::find_edge(&r.level, 4, 6).unwrap();
        let got = p1[cube.num_faces() + e].coords;
        assert!(
            (got - edge).norm() <= EXACT_TOL * d,
            "s={s}: edge point {got:?}, expected {edge:?}"
        );
        let got = p1[descendant(&h, 1, 4)].coords;
        assert!(
            (got - vertex).norm() <= EXACT_TOL * d,
            "s={s}: vertex point {got:?}, expected {vertex:?}"
        );
    }
}

/// Sharpness 10 and above is infinite: 10, 12 and 1e6 refine and limit
/// identically, while 9.5 decays (same refined points to level 3, different limit).
#[test]
fn sharpness_of_ten_or_more_is_infinite() {
    let cube = perturbed(subdyn::examples::cube(), 0.1, 6);
    let p = &cube.positions;
    let run = |s: f64| {
        let h = refiner(&cube, BoundaryRule::EdgeAndCorner, &loop_creases(s))
            .refine_uniform(3)
            .unwrap();
        let p3 = h.stencil_to_level(3).unwrap().apply(p).unwrap();
        let lim = limit_stencil(&h, 1).unwrap().apply(p).unwrap();
        (p3, lim)
    };
    let (p10, l10) = run(10.0);
    for s in [12.0, 1e6] {
        let (ps, ls) = run(s);
        assert_eq!(ps, p10, "s={s}: refined points differ from s=10");
        assert_eq!(ls, l10, "s={s}: limit positions differ from s=10");
    }
    let (p95, l95) = run(9.5);
    assert!(
        max_pairwise(&p95, &p10) <= EXACT_TOL,
        "s=9.5 differs from s=10 by level 3"
    );
    assert!(
        max_pairwise(&l95, &l10) > 1e-9,
        "s=9.5 has the limit of an infinite crease"
    );
}

#[test]
fn isolated_vertex_is_carried_along_unchanged() {
    let mesh = mixed_mesh();
    let mut with = mesh.clone();
    let lonely = Point3::new(5.0, -4.0, 2.5);
    with.positions.push(lonely);
    let iso = with.num_vertices() - 1;
    let h = default_refiner(&with).refine_uniform(3).unwrap();
    let h0 = default_refiner(&mesh).refine_uniform(3).unwrap();
    for k in 1..=3 {
        let s = h.stencil_to_level(k).unwrap();
        let last = s.num_rows() - 1;
        assert_eq!(
            descendant(&h, k, iso),
            last,
            "level {k}: isolated vertex is not last"
        );
        let (c, w) = s.row(last);
        assert_eq!(
            (c, w),
            (&[iso as u32][..], &[1.0][..]),
            "level {k}: isolated vertex row"
        );
        let pk = s.apply(&with.positions).unwrap();
        assert_eq!(pk[last], lonely, "level {k}: isolated vertex moved");
        // Everything else is refined exactly as without it.
        let p0k = h0
            .stencil_to_level(k)
            .unwrap()
            .apply(&mesh.positions)
            .unwrap();
        assert_eq!(pk.len(), p0k.len() + 1);
        let err = max_pairwise(&pk[..last], &p0k);
        assert!(
            err <= EXACT_TOL,
            "level {k}: the isolated vertex changed other points by {err:e}"
        );
    }
    let lp = limit_stencil(&h, 2)
        .unwrap()
        .apply(&with.positions)
        .unwrap();
    assert_eq!(
        lp[descendant(&h, 2, iso)],
        lonely,
        "isolated vertex limit position"
    );
}

// ---------------------------------------------------------------------------
// Boundary rules

#[test]
fn edge_and_corner_keeps_corners_edge_only_moves_them() {
    let quad = single_quad();
    let p = &quad.positions;
    let h = default_refiner(&quad).refine_uniform(4).unwrap();
    for k in 1..=4 {
        let pk = h.stencil_to_level(k).unwrap().apply(p).unwrap();
        for v in 0..4 {
            assert_eq!(
                pk[descendant(&h, k, v)],
                p[v],
                "edge-and-corner: corner {v} moved at level {k}"
            );
        }
    }
    let lp = limit_stencil(&h, 0).unwrap().apply(p).unwrap();
    for v in 0..4 {
        assert_eq!(lp[v], p[v], "edge-and-corner: corner {v} limit moved");
    }

    let h = refiner(&quad, BoundaryRule::EdgeOnly, &[])
        .refine_uniform(2)
        .unwrap();
    let p1 = h.stencil_to_level(1).unwrap().apply(p).unwrap();
    let lp = limit_stencil(&h, 0).unwrap().apply(p).unwrap();
    let d = diag(p);
    for v in 0..4 {
        let (a, b) = (p[(v + 3) % 4].coords, p[(v + 1) % 4].coords);
        let expect = Point3::from((a + 6.0 * p[v].coords + b) / 8.0);
        let got = p1[descendant(&h, 1, v)];
        assert!(
            (got - expect).norm() <= EXACT_TOL * d,
            "edge-only: corner {v} at level 1 is {got}, expected {expect}"
        );
        let expect = Point3::from((a + 4.0 * p[v].coords + b) / 6.0);
        assert!(
            (lp[v] - expect).norm() <= EXACT_TOL * d,
            "edge-only: corner {v} limit is {}, expected {expect}",
            lp[v]
        );
    }
}

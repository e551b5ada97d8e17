//! Agreement with the second set of OpenSubdiv 3.6 references
//! (`tests/data/opensubdiv-extra/README.md`): n-gons, triangles, semi-sharp
//! and infinitely sharp creases, darts, edge-only boundaries.
//!
//! `NAME.bfr.txt` is Bfr with its default approximation (level 2 near
//! extraordinary vertices, Gregory patches inside); `NAME.bfr_exact.txt` is
//! Bfr at its deepest level (10). subdyn evaluates exactly, so it is compared
//! with the default file where that file is exact (quads, creases, darts) and
//! with the deepest one on n-gons. At an extraordinary vertex the parametric
//! derivative has no limit (it scales like (2λ)^level), so derivatives are
//! compared there only against the default file, whose level-2 convention
//! subdyn follows.
//!
//! Darts (an infinitely sharp crease ending inside the surface) are the one
//! place where subdyn deliberately differs: OpenSubdiv applies the smooth
//! limit mask there at whatever level it stops (level 3 in `limit.xyz`,
//! level 2 in Bfr), which is not the limit; subdyn follows the dart down
//! until the mask converges. At darts the tests check that subdyn is closer
//! to Bfr's deepest evaluation than OpenSubdiv's own defaults are.

mod common;

use std::path::PathBuf;

use common::{BfrSample, descendant, max_nearest, read_bfr, read_xyz};
use subdyn::io::{read_mesh, read_tags};
use subdyn::limit::{LimitEvaluator, limit_stencil};
use subdyn::math::Point3;
use subdyn::math::bbox_diagonal;
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{BoundaryRule, Hierarchy, RefineOptions, Refiner};
use subdyn::topology::VertexRule;

const POSITION_TOL: f64 = 1e-9;
const DERIVATIVE_TOL: f64 = 1e-7;

fn file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/opensubdiv-extra")
        .join(name)
}

fn setup(name: &str, boundary: BoundaryRule) -> (PolyMesh, Refiner) {
    let mesh = read_mesh(file(&format!("{name}.obj"))).expect("reference mesh");
    let creases_path = file(&format!("{name}.creases"));
    let creases = if creases_path.exists() {
        read_tags(&creases_path).expect("crease file").creases
    } else {
        Vec::new()
    };
    let options = RefineOptions {
        boundary,
        creases,
        ..Default::default()
    };
    let refiner = Refiner::new(&mesh, &options).expect("valid mesh");
    (mesh, refiner)
}

const MESHES: [(&str, BoundaryRule); 6] = [
    ("ngon_mix", BoundaryRule::EdgeAndCorner),
    ("tri_tet", BoundaryRule::EdgeAndCorner),
    ("crease_cube", BoundaryRule::EdgeAndCorner),
    ("grid_edgeonly", BoundaryRule::EdgeOnly),
    ("fan5_edgeonly", BoundaryRule::EdgeOnly),
    ("dart", BoundaryRule::EdgeAndCorner),
];

/// Base vertices that are darts once semi-sharp creases have decayed.
fn base_darts(h: &Hierarchy, refiner: &Refiner) -> Vec<usize> {
    let k = h.num_levels();
    (0..refiner.level.num_vertices)
        .filter(|&v| {
            let d = descendant(h, k, v);
            h.sharpness[k].rule(h.level(k), d) == VertexRule::Dart
        })
        .collect()
}

#[test]
fn level_3_and_limit_positions_match() {
    for (name, boundary) in MESHES {
        let (mesh, refiner) = setup(name, boundary);
        let h = refiner.refine_uniform(3).unwrap();
        let diag = bbox_diagonal(&mesh.positions);
        let p3 = h
            .stencil_to_level(3)
            .unwrap()
            .apply(&mesh.positions)
            .unwrap();
        let reference = read_mesh(file(&format!("{name}.L3.obj"))).unwrap();
        assert_eq!(p3.len(), reference.num_vertices(), "{name}: vertex count");
        assert_eq!(
            h.level(3).num_faces(),
            reference.num_faces(),
            "{name}: face count"
        );
        let d = max_nearest(&p3, &reference.positions).max(max_nearest(&reference.positions, &p3));
        assert!(
            d / diag < POSITION_TOL,
            "{name}: level-3 points differ by {:e} of the diagonal",
            d / diag
        );
        // Limit points, darts aside (see the module docs).
        let limit = limit_stencil(&h, 3)
            .unwrap()
            .apply(&mesh.positions)
            .unwrap();
        let darts: Vec<usize> = base_darts(&h, &refiner)
            .iter()
            .map(|&v| descendant(&h, 3, v))
            .collect();
        let ours: Vec<Point3> = (0..limit.len())
            .filter(|i| !darts.contains(i))
            .map(|i| limit[i])
            .collect();
        let theirs = read_xyz(&file(&format!("{name}.limit.xyz")));
        assert_eq!(theirs.len(), limit.len(), "{name}: limit point count");
        let d = max_nearest(&ours, &theirs);
        assert!(
            d / diag < POSITION_TOL,
            "{name}: limit points differ by {:e} of the diagonal",
            d / diag
        );
    }
}

#[test]
fn dart_limits_are_closer_to_the_deepest_bfr_than_opensubdiv_defaults() {
    for name in ["crease_cube", "dart"] {
        let (mesh, refiner) = setup(name, BoundaryRule::EdgeAndCorner);
        let h = refiner.refine_uniform(3).unwrap();
        let darts = base_darts(&h, &refiner);
        assert!(!darts.is_empty(), "{name} has darts");
        let eval = LimitEvaluator::new(&refiner);
        let default = read_bfr(&file(&format!("{name}.bfr.txt")));
        let deepest = read_bfr(&file(&format!("{name}.bfr_exact.txt")));
        let mut checked = 0;
        for (a, b) in default.iter().zip(&deepest) {
            if !at_vertex(&mesh, b).is_some_and(|v| darts.contains(&v)) {
                continue;
            }
            let ours = eval.evaluate(b.face, b.u, b.v, &mesh.positions).unwrap().p;
            let (e_ours, e_default) = ((ours - b.p).norm(), (a.p - b.p).norm());
            assert!(
                e_ours < 0.05 * e_default,
                "{name} face {} ({}, {}): subdyn is {e_ours:e} from Bfr level 10, Bfr default {e_default:e}",
                b.face,
                b.u,
                b.v
            );
            checked += 1;
        }
        assert!(checked > 0, "{name}: no dart corner sampled");
    }
}

/// The base vertex a sample sits on, for quad corners.
fn at_vertex(mesh: &PolyMesh, s: &BfrSample) -> Option<usize> {
    let face = mesh.face(s.face);
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let i = corners.iter().position(|&c| c == (s.u, s.v))?;
    (face.len() == 4).then(|| face[i] as usize)
}

/// True when the sample sits on a vertex of valence other than 4: a corner
/// of a quad at such a vertex, or the corner or centre of an n-gon's sub-face.
fn at_extraordinary_vertex(mesh: &PolyMesh, refiner: &Refiner, s: &BfrSample) -> bool {
    let face = mesh.face(s.face);
    let level = &refiner.level;
    let valence = |v: u32| level.valence(v as usize);
    if face.len() == 4 {
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        corners
            .iter()
            .position(|&c| c == (s.u, s.v))
            .is_some_and(|i| valence(face[i]) != 4)
    } else {
        (s.u == 0.0 && s.v == 0.0 && valence(face[0]) != 4) || (s.u == 0.5 && s.v == 0.5)
    }
}

fn compare(name: &str, boundary: BoundaryRule, reference: &str, derivatives_at_ev: bool) {
    let (mesh, refiner) = setup(name, boundary);
    let eval = LimitEvaluator::new(&refiner);
    let diag = bbox_diagonal(&mesh.positions);
    let (mut worst_p, mut worst_d) = (0.0f64, 0.0f64);
    let samples = read_bfr(&file(&format!("{name}.{reference}.txt")));
    assert!(!samples.is_empty());
    let darts = base_darts(&refiner.refine_uniform(3).unwrap(), &refiner);
    for s in &samples {
        let e = eval.evaluate(s.face, s.u, s.v, &mesh.positions).unwrap();
        if !at_vertex(&mesh, s).is_some_and(|v| darts.contains(&v)) {
            worst_p = worst_p.max((e.p - s.p).norm() / diag);
        }
        if derivatives_at_ev || !at_extraordinary_vertex(&mesh, &refiner, s) {
            let d = (e.du - s.du).norm().max((e.dv - s.dv).norm()) / diag;
            worst_d = worst_d.max(d);
        }
    }
    assert!(
        worst_p < POSITION_TOL,
        "{name} vs {reference}: position error {worst_p:e}"
    );
    assert!(
        worst_d < DERIVATIVE_TOL,
        "{name} vs {reference}: derivative error {worst_d:e}"
    );
}

#[test]
fn bfr_samples_match_on_creases_darts_and_edge_only_boundaries() {
    for (name, boundary) in MESHES.into_iter().skip(2) {
        compare(name, boundary, "bfr", true);
    }
}

#[test]
fn bfr_exact_samples_match_on_ngons_and_triangles() {
    for (name, boundary) in MESHES.into_iter().take(2) {
        compare(name, boundary, "bfr_exact", false);
    }
}

#[test]
fn default_bfr_differs_on_ngons_only_by_its_approximation() {
    // Documents the known difference: Bfr's default Gregory approximation
    // near the centre of a pentagon is off the exact limit by more than 1e-4.
    let (mesh, refiner) = setup("ngon_mix", BoundaryRule::EdgeAndCorner);
    let eval = LimitEvaluator::new(&refiner);
    let default = read_bfr(&file("ngon_mix.bfr.txt"));
    let exact = read_bfr(&file("ngon_mix.bfr_exact.txt"));
    let mut largest_gap = 0.0f64;
    for (a, b) in default.iter().zip(&exact) {
        let e = eval.evaluate(b.face, b.u, b.v, &mesh.positions).unwrap();
        assert!((e.p - b.p).norm() < 1e-12, "exact sample {b:?}");
        largest_gap = largest_gap.max((a.p - b.p).norm());
    }
    assert!(
        largest_gap > 1e-4,
        "default Bfr is expected to approximate (gap {largest_gap:e})"
    );
}

//! Doo-Sabin and non-uniform Catmull-Clark refinement, and the Doo-Sabin →
//! non-uniform Catmull-Clark conversion: stencil rows sum to one, affine
//! invariance, reproduction of (non-uniform) B-spline knot insertion on
//! regular torus grids checked by an independent de Boor evaluator, equal
//! intervals = uniform Catmull-Clark, and the conversion's limit surface.

use subdyn::finetune::doo_sabin_to_non_uniform;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{
    BoundaryRule, NonUniformHierarchy, RefineOptions, Refiner, doo_sabin_refine,
};
use subdyn::topology::Level;

/// Deterministic pseudo-random numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A torus grid with its vertices jittered (so no accidental symmetry helps).
fn bumpy_torus(n: usize, m: usize, seed: u64) -> PolyMesh {
    let mut t = subdyn::examples::torus(n, m, 2.0, 0.7);
    let mut rng = Lcg(seed);
    for p in &mut t.positions {
        *p += Vector3::new(rng.next(), rng.next(), rng.next()) * 0.2;
    }
    t
}

/// An open `k × k` grid of quads with random heights; vertex `(i, j)` at `(i, j, h)`.
fn height_grid(k: usize, seed: u64) -> PolyMesh {
    let mut rng = Lcg(seed);
    let positions = (0..k * k)
        .map(|v| Point3::new((v / k) as f64, (v % k) as f64, rng.next()))
        .collect();
    let id = |i: usize, j: usize| (i * k + j) as u32;
    let faces: Vec<Vec<u32>> = (0..k - 1)
        .flat_map(|i| {
            (0..k - 1).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolyMesh::from_faces(positions, &faces).unwrap()
}

/// A closed mesh with a triangle, quads and a pentagon: a cube with one face
/// split into a triangle and a pentagon... built as a pentagonal prism with
/// one quad side split into two triangles.
fn mixed_mesh() -> PolyMesh {
    use std::f64::consts::TAU;
    let mut positions = Vec::new();
    for z in [0.0, 1.3] {
        for k in 0..5 {
            let a = TAU * k as f64 / 5.0;
            positions.push(Point3::new(
                a.cos() + 0.1 * k as f64,
                a.sin(),
                z + 0.05 * k as f64,
            ));
        }
    }
    let mut faces = vec![vec![4, 3, 2, 1, 0], vec![5, 6, 7, 8, 9]];
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        if k == 2 {
            faces.push(vec![k, k1, k1 + 5]);
            faces.push(vec![k, k1 + 5, k + 5]);
        } else {
            faces.push(vec![k, k1, k1 + 5, k + 5]);
        }
    }
    PolyMesh::from_faces(positions, &faces).unwrap()
}

fn max_dist(a: &[Point3], b: &[Point3]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------
// An independent periodic B-spline evaluator (de Boor).

/// Point at parameter `x` of the periodic B-spline of degree `p` whose
/// segment `k` uses controls `k..=k+p` (mod n) and has length `len[k]`;
/// segment `first` starts at parameter 0.
fn eval_periodic(p: usize, ctrl: &[Point3], len: &[f64], first: usize, x: f64) -> Point3 {
    let n = ctrl.len();
    let total: f64 = len.iter().sum();
    let mut x = x.rem_euclid(total);
    let mut k = first;
    loop {
        if len[k % n] > 0.0 && x < len[k % n] {
            break;
        }
        x -= len[k % n];
        k += 1;
    }
    // Knots t(j), j in k+1 ..= k+2p, with t(k+p) = 0 and t(j+1) - t(j) = len[j - p].
    let seg = |j: usize| len[(j + n * 4 - p) % n];
    let t = |j: usize| -> f64 {
        let base = k + p;
        if j >= base {
            (base..j).map(seg).sum()
        } else {
            -(j..base).map(seg).sum::<f64>()
        }
    };
    let mut d: Vec<Point3> = (0..=p).map(|r| ctrl[(k + r) % n]).collect();
    for r in 1..=p {
        for i in (r..=p).rev() {
            let j = k + i;
            let a = (x - t(j)) / (t(j + p + 1 - r) - t(j));
            d[i] = Point3::from(d[i - 1].coords * (1.0 - a) + d[i].coords * a);
        }
    }
    d[p]
}

/// Tensor-product periodic surface: `grid[i][j]`, segments in `u` and `v`.
#[allow(clippy::too_many_arguments)]
fn eval_surface(
    p: usize,
    grid: &[Vec<Point3>],
    lu: &[f64],
    fu: usize,
    lv: &[f64],
    fv: usize,
    u: f64,
    v: f64,
) -> Point3 {
    let m = grid[0].len();
    let col: Vec<Point3> = (0..m)
        .map(|j| {
            let row: Vec<Point3> = grid.iter().map(|r| r[j]).collect();
            eval_periodic(p, &row, lu, fu, u)
        })
        .collect();
    eval_periodic(p, &col, lv, fv, v)
}

/// Torus vertex `(i, j)` of `examples::torus(n, m, ..)` is `i * m + j`.
fn torus_grid(mesh: &PolyMesh, n: usize, m: usize) -> Vec<Vec<Point3>> {
    (0..n)
        .map(|i| (0..m).map(|j| mesh.positions[i * m + j]).collect())
        .collect()
}

// ---------------------------------------------------------------------------
// Doo-Sabin

#[test]
fn doo_sabin_rows_sum_to_one_and_children_are_valid_meshes() {
    for mesh in [subdyn::examples::cube(), mixed_mesh(), height_grid(4, 3)] {
        let h = doo_sabin_refine(&mesh, 3).unwrap();
        for s in &h.stencils {
            for (r, sum) in s.row_sums().iter().enumerate() {
                assert!((sum - 1.0).abs() < 1e-14, "row {r} sums to {sum}");
            }
        }
        for child in &h.meshes[1..] {
            // Manifold and consistently oriented (from_mesh checks both).
            Level::from_mesh(child).unwrap();
        }
    }
    // The cube: 6 F-faces + 12 E-faces + 8 V-faces; Euler characteristic kept.
    let h = doo_sabin_refine(&subdyn::examples::cube(), 2).unwrap();
    let l = Level::from_mesh(h.finest()).unwrap();
    let chi = l.num_vertices as i64 - l.num_edges() as i64 + l.num_faces() as i64;
    assert_eq!(chi, 2);
}

#[test]
fn doo_sabin_is_affine_invariant() {
    let mesh = mixed_mesh();
    let a = nalgebra::Matrix3::new(1.2, 0.3, -0.4, 0.1, 0.9, 0.2, -0.5, 0.4, 1.1);
    let t = Vector3::new(3.0, -2.0, 0.5);
    let map = |p: &Point3| Point3::from(a * p.coords + t);
    let mut moved = mesh.clone();
    moved.positions = mesh.positions.iter().map(map).collect();
    let h0 = doo_sabin_refine(&mesh, 2).unwrap();
    let h1 = doo_sabin_refine(&moved, 2).unwrap();
    let expected: Vec<Point3> = h0.finest().positions.iter().map(map).collect();
    assert!(max_dist(&expected, &h1.finest().positions) < 1e-12);
}

#[test]
fn doo_sabin_on_a_regular_grid_is_biquadratic_knot_insertion() {
    let (n, m) = (6, 5);
    let mesh = bumpy_torus(n, m, 7);
    let h = doo_sabin_refine(&mesh, 1).unwrap();
    let coarse = torus_grid(&mesh, n, m);
    // Child vertex = parent corner c = 4 f + k of face f = (i, j) whose corners
    // are (i,j), (i+1,j), (i+1,j+1), (i,j+1): Chaikin index 2i + a, 2j + b.
    let mut fine = vec![vec![Point3::origin(); 2 * m]; 2 * n];
    for i in 0..n {
        for j in 0..m {
            let f = i * m + j;
            for (k, (a, b)) in [(0, 0), (1, 0), (1, 1), (0, 1)].iter().enumerate() {
                let c = 4 * f + k;
                fine[2 * i + a][2 * j + b] = h.meshes[1].positions[c];
            }
        }
    }
    let (lu0, lv0) = (vec![1.0; n], vec![1.0; m]);
    let (lu1, lv1) = (vec![0.5; 2 * n], vec![0.5; 2 * m]);
    let mut rng = Lcg(11);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (u, v) = (rng.next() * n as f64, rng.next() * m as f64);
        let p0 = eval_surface(2, &coarse, &lu0, 0, &lv0, 0, u, v);
        let p1 = eval_surface(2, &fine, &lu1, 0, &lv1, 0, u, v);
        worst = worst.max((p0 - p1).norm());
    }
    assert!(
        worst < 1e-12,
        "Doo-Sabin level 1 moves the surface by {worst}"
    );
}

#[test]
fn doo_sabin_limit_on_an_open_grid_is_the_biquadratic_spline() {
    // Level-3 face centroids are surface points at knot crossings; with
    // vertex (i, j) at (i, j, h) the surface is (u − 1.5, v − 1.5, z(u, v)).
    let k = 5;
    let mesh = height_grid(k, 5);
    let h = doo_sabin_refine(&mesh, 3).unwrap();
    let heights: Vec<f64> = mesh.positions.iter().map(|p| p.z).collect();
    let basis = |t: f64, i: usize| -> f64 {
        // uniform quadratic B-spline N(t - i), support [i, i + 3]
        let s = t - i as f64;
        if !(0.0..3.0).contains(&s) {
            0.0
        } else if s < 1.0 {
            0.5 * s * s
        } else if s < 2.0 {
            0.5 * (-2.0 * s * s + 6.0 * s - 3.0)
        } else {
            0.5 * (3.0 - s) * (3.0 - s)
        }
    };
    let fine = h.finest();
    let mut checked = 0;
    for face in fine.faces() {
        let c = face.iter().fold(Vector3::zeros(), |acc, &v| {
            acc + fine.positions[v as usize].coords
        }) / face.len() as f64;
        let (u, v) = (c.x + 1.5, c.y + 1.5);
        let mut z = 0.0;
        for i in 0..k {
            for j in 0..k {
                z += basis(u, i) * basis(v, j) * heights[i * k + j];
            }
        }
        assert!(
            (z - c.z).abs() < 1e-12,
            "centroid ({}, {}) off the surface by {}",
            c.x,
            c.y,
            z - c.z
        );
        checked += 1;
    }
    assert!(checked > 100);
}

// ---------------------------------------------------------------------------
// Non-uniform Catmull-Clark

#[test]
fn equal_intervals_reproduce_uniform_catmull_clark() {
    for (mesh, d) in [
        (subdyn::examples::cube(), 1.0),
        (mixed_mesh(), 2.5),
        (bumpy_torus(5, 4, 3), 0.3),
        (height_grid(4, 9), 1.0),
    ] {
        let options = RefineOptions {
            boundary: BoundaryRule::EdgeAndCorner,
            creases: Vec::new(),
            ..Default::default()
        };
        let uniform = Refiner::new(&mesh, &options)
            .unwrap()
            .refine_uniform(3)
            .unwrap();
        let expected = uniform
            .stencil_to_level(3)
            .unwrap()
            .apply(&mesh.positions)
            .unwrap();
        let level = Level::from_mesh(&mesh).unwrap();
        let ne = level.num_edges();
        let h = NonUniformHierarchy::new(level, vec![d; ne], 3).unwrap();
        let got = h
            .stencil_to_level(3)
            .unwrap()
            .apply(&mesh.positions)
            .unwrap();
        assert_eq!(h.levels[3].face_verts, uniform.level(3).face_verts);
        let err = max_dist(&expected, &got);
        assert!(
            err < 1e-12,
            "non-uniform with equal intervals differs by {err}"
        );
        for s in &h.stencils {
            assert!(s.row_sums().iter().all(|x| (x - 1.0).abs() < 1e-13));
        }
    }
}

/// Non-uniform intervals on a torus: `a[i]` on edges `(i, j)–(i+1, j)`, `b[j]` on `(i, j)–(i, j+1)`.
fn tensor_intervals(level: &Level, m: usize, a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len();
    level
        .edge_verts
        .iter()
        .map(|&[p, q]| {
            let (pi, pj) = (p as usize / m, p as usize % m);
            let (qi, qj) = (q as usize / m, q as usize % m);
            if pj == qj {
                let i = if (pi + 1) % n == qi { pi } else { qi };
                a[i]
            } else {
                assert_eq!(pi, qi);
                let j = if (pj + 1) % m == qj { pj } else { qj };
                b[j]
            }
        })
        .collect()
}

#[test]
fn non_uniform_intervals_on_a_grid_are_bicubic_knot_insertion() {
    check_knot_insertion(&[1.0; 6], &[1.0; 5]);
    check_knot_insertion(&[1.0, 0.4, 2.0, 1.3, 0.7, 0.2], &[0.5, 1.5, 1.0, 3.0, 0.8]);
    // Zero intervals (double knots), as in converted Doo-Sabin meshes.
    check_knot_insertion(&[1.0, 0.0, 1.0, 0.0, 1.0, 0.0], &[0.0, 1.0, 0.0, 1.0]);
    check_knot_insertion(&[1.0, 0.05, 1.0, 0.05, 1.0, 0.05], &[2.0, 0.0, 1.0, 0.0]);
}

fn check_knot_insertion(a: &[f64], b: &[f64]) {
    let (n, m) = (a.len(), b.len());
    let mesh = bumpy_torus(n, m, 21);
    let level = Level::from_mesh(&mesh).unwrap();
    let d = tensor_intervals(&level, m, a, b);
    let (nf, ne) = (level.num_faces(), level.num_edges());
    let h = NonUniformHierarchy::new(level.clone(), d, 1).unwrap();
    let p1 = h.stencils[0].apply(&mesh.positions).unwrap();
    // Child grid: (2i, 2j) vertex point, (2i+1, 2j) u-edge point,
    // (2i, 2j+1) v-edge point, (2i+1, 2j+1) face point.
    let edge_of = |p: usize, q: usize| -> usize {
        (0..ne)
            .find(|&e| {
                let [x, y] = level.edge_verts[e];
                (x as usize, y as usize) == (p, q) || (x as usize, y as usize) == (q, p)
            })
            .unwrap()
    };
    let id = |i: usize, j: usize| (i % n) * m + (j % m);
    let mut fine = vec![vec![Point3::origin(); 2 * m]; 2 * n];
    for i in 0..n {
        for j in 0..m {
            fine[2 * i][2 * j] = p1[nf + ne + id(i, j)];
            fine[2 * i + 1][2 * j] = p1[nf + edge_of(id(i, j), id(i + 1, j))];
            fine[2 * i][2 * j + 1] = p1[nf + edge_of(id(i, j), id(i, j + 1))];
            fine[2 * i + 1][2 * j + 1] = p1[i * m + j];
        }
    }
    let coarse = torus_grid(&mesh, n, m);
    // Cubic segment k has middle leg k+1: length d[k+1]; segment 0 at 0.
    let seg = |d: &[f64]| -> Vec<f64> { (0..d.len()).map(|k| d[(k + 1) % d.len()]).collect() };
    let half = |d: &[f64]| -> Vec<f64> { d.iter().flat_map(|x| [x / 2.0, x / 2.0]).collect() };
    let (lu0, lv0) = (seg(a), seg(b));
    let (lu1, lv1) = (seg(&half(a)), seg(&half(b)));
    let (tu, tv) = (a.iter().sum::<f64>(), b.iter().sum::<f64>());
    let mut rng = Lcg(5);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (u, v) = (rng.next() * tu, rng.next() * tv);
        let q0 = eval_surface(3, &coarse, &lu0, 0, &lv0, 0, u, v);
        // Same parameter (the halves add up); parent segment 0 is child segment 1.
        let q1 = eval_surface(3, &fine, &lu1, 1, &lv1, 1, u, v);
        worst = worst.max((q0 - q1).norm());
    }
    assert!(
        worst < 1e-12,
        "non-uniform step moves the surface by {worst} ({a:?}, {b:?})"
    );
}

#[test]
fn bad_intervals_are_refused() {
    let level = Level::from_mesh(&subdyn::examples::cube()).unwrap();
    let ne = level.num_edges();
    assert!(NonUniformHierarchy::new(level.clone(), vec![1.0; ne - 1], 1).is_err());
    let mut d = vec![1.0; ne];
    d[3] = f64::NAN;
    assert!(NonUniformHierarchy::new(level.clone(), d.clone(), 1).is_err());
    d[3] = -1.0;
    assert!(NonUniformHierarchy::new(level.clone(), d, 1).is_err());
    assert!(NonUniformHierarchy::new(level, vec![1.0; ne], 9).is_err());
}

// ---------------------------------------------------------------------------
// Conversion

/// The converted torus as a `2n × 2m` cubic grid: the corner of face `(i, j)`
/// at vertex `(i + a, j + b)` is cubic control point `(2i + a + 1, 2j + b + 1)`.
fn converted_grid(points: &[Point3], n: usize, m: usize) -> Vec<Vec<Point3>> {
    let mut g = vec![vec![Point3::origin(); 2 * m]; 2 * n];
    for i in 0..n {
        for j in 0..m {
            for (k, (a, b)) in [(0, 0), (1, 0), (1, 1), (0, 1)].iter().enumerate() {
                g[(2 * i + a + 1) % (2 * n)][(2 * j + b + 1) % (2 * m)] =
                    points[4 * (i * m + j) + k];
            }
        }
    }
    g
}

#[test]
fn conversion_of_a_regular_mesh_keeps_the_limit_surface() {
    let (n, m) = (5, 6);
    let mesh = bumpy_torus(n, m, 33);
    let conv = doo_sabin_to_non_uniform(&mesh, 0.0).unwrap();
    assert!((0..conv.level.num_vertices).all(|v| conv.level.valence(v) == 4));
    assert!(
        conv.stencil
            .row_sums()
            .iter()
            .all(|s| (s - 1.0).abs() < 1e-14)
    );
    let quad = torus_grid(&mesh, n, m);
    let cubic = converted_grid(&conv.mesh.positions, n, m);
    // Cubic legs (2i, 2i+1) have interval 1, (2i+1, 2i+2) interval 0;
    // segment k has middle leg k + 1; segment 2i − 1 (around P_i) starts at
    // i − 1, so segment 1 starts at 0.
    let lens = |k: usize| -> Vec<f64> {
        (0..2 * k)
            .map(|s| if (s + 1) % 2 == 0 { 1.0 } else { 0.0 })
            .collect()
    };
    let (lu, lv) = (lens(n), lens(m));
    let mut rng = Lcg(8);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (u, v) = (rng.next() * n as f64, rng.next() * m as f64);
        let q = eval_surface(2, &quad, &vec![1.0; n], 0, &vec![1.0; m], 0, u, v);
        let c = eval_surface(3, &cubic, &lu, 1, &lv, 1, u, v);
        worst = worst.max((q - c).norm());
    }
    assert!(worst < 1e-9, "converted surface differs by {worst}");
}

#[test]
fn conversion_refuses_bad_epsilon() {
    let cube = subdyn::examples::cube();
    assert!(doo_sabin_to_non_uniform(&cube, f64::NAN).is_err());
    assert!(doo_sabin_to_non_uniform(&cube, -0.1).is_err());
    let c = doo_sabin_to_non_uniform(&cube, 0.05).unwrap();
    assert_eq!(c.level.num_faces(), 6 + 12 + 8);
}

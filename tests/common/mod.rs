//! Shared fixtures and helpers of the integration tests `refine`, `limit` and
//! `topology`: small hand-built meshes, the OpenSubdiv 3.6 references under
//! `tests/data/opensubdiv/`, a deterministic random generator, point-set
//! distances and the quad / quad-sub-face parameterisation of faces.
//!
//! Every test file uses a different subset of these helpers.
#![allow(dead_code)]

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use subdyn::math::{Point3, Vector3, bbox_diagonal};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{BoundaryRule, Hierarchy, RefineOptions, Refiner};

/// The four meshes with OpenSubdiv 3.6 references.
pub const REFERENCE_MESHES: [&str; 4] = ["cube", "fan5_open", "grid4_open", "torus_regular"];

/// Sharpness used for "infinitely sharp" creases in fixtures.
pub const INFINITE: f64 = 10.0;

// ---------------------------------------------------------------------------
// Files

/// A file under `tests/data/opensubdiv/`.
pub fn opensubdiv(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/opensubdiv")
        .join(name)
}

/// The base mesh `NAME.obj` of an OpenSubdiv reference.
pub fn reference_mesh(name: &str) -> PolyMesh {
    subdyn::io::read_mesh(opensubdiv(&format!("{name}.obj")))
        .unwrap_or_else(|e| panic!("reading {name}.obj: {e}"))
}

/// Whitespace-separated numbers of every non-empty line of a text file.
pub fn numeric_lines(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|l| {
            l.split_whitespace()
                .map(|x| {
                    x.parse()
                        .unwrap_or_else(|e| panic!("{}: {l:?}: {e}", path.display()))
                })
                .collect()
        })
        .collect()
}

/// The points of an `x y z` file.
pub fn read_xyz(path: &Path) -> Vec<Point3> {
    numeric_lines(path)
        .iter()
        .map(|r| {
            assert_eq!(
                r.len(),
                3,
                "{}: expected 3 numbers per line",
                path.display()
            );
            Point3::new(r[0], r[1], r[2])
        })
        .collect()
}

/// One line of a `NAME.bfr.txt` reference: `face u v P Du Dv`.
#[derive(Clone, Copy, Debug)]
pub struct BfrSample {
    /// Base face.
    pub face: usize,
    /// First parameter.
    pub u: f64,
    /// Second parameter.
    pub v: f64,
    /// Limit position.
    pub p: Point3,
    /// ∂P/∂u.
    pub du: Vector3,
    /// ∂P/∂v.
    pub dv: Vector3,
}

/// All samples of a `NAME.bfr.txt` reference.
pub fn read_bfr(path: &Path) -> Vec<BfrSample> {
    numeric_lines(path)
        .iter()
        .map(|r| {
            assert_eq!(
                r.len(),
                12,
                "{}: expected 12 numbers per line",
                path.display()
            );
            BfrSample {
                face: r[0] as usize,
                u: r[1],
                v: r[2],
                p: Point3::new(r[3], r[4], r[5]),
                du: Vector3::new(r[6], r[7], r[8]),
                dv: Vector3::new(r[9], r[10], r[11]),
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Random numbers

/// A small deterministic generator (xorshift64*), so tests need no `rand`.
pub struct Rng(u64);

impl Rng {
    /// A generator with a fixed seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[a, b)`.
    pub fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next_f64()
    }

    /// Uniform integer in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_f64() * n as f64) as usize).min(n - 1)
    }

    /// A vector with coordinates uniform in `[-1, 1)`.
    pub fn vector(&mut self) -> Vector3 {
        Vector3::new(
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
        )
    }
}

// ---------------------------------------------------------------------------
// Fixture meshes

fn mesh(positions: Vec<Point3>, faces: &[&[u32]]) -> PolyMesh {
    let faces: Vec<Vec<u32>> = faces.iter().map(|f| f.to_vec()).collect();
    PolyMesh::from_faces(positions, &faces).expect("fixture mesh is valid")
}

/// An open, non-planar mesh mixing a pentagon, quads and triangles, with a
/// boundary that has valence-2 vertices (corners under edge-and-corner).
///
/// Vertices 0–4: a pentagon (radius 1); 5–9: an outer ring (radius 2.2);
/// 10, 11: a tab quad hanging off the outer edge (7, 8). Faces: the pentagon
/// `[0 1 2 3 4]`, two triangles `[1 0 5]`, `[1 5 6]`, four quads
/// `[i+1, i, 5+i, 5+i+1]` (i = 1…4) and the tab `[8 7 10 11]`.
/// Interior vertices: 0 (valence 3), 1 (valence 4 with two triangles), 2, 3, 4.
pub fn mixed_mesh() -> PolyMesh {
    let mut p = Vec::new();
    let z = [0.10, -0.05, 0.20, 0.00, -0.15];
    for (i, zi) in z.iter().enumerate() {
        let a = TAU * i as f64 / 5.0;
        p.push(Point3::new(a.cos(), a.sin(), *zi));
    }
    let zo = [-0.30, 0.25, 0.05, -0.20, 0.35];
    for (i, zi) in zo.iter().enumerate() {
        let a = TAU * i as f64 / 5.0 + 0.1;
        p.push(Point3::new(2.2 * a.cos(), 2.2 * a.sin(), *zi));
    }
    for (i, zi) in [(2usize, 0.4), (3, -0.1)] {
        let a = TAU * i as f64 / 5.0 + 0.15;
        p.push(Point3::new(3.1 * a.cos(), 3.1 * a.sin(), zi));
    }
    mesh(
        p,
        &[
            &[0, 1, 2, 3, 4],
            &[1, 0, 5],
            &[1, 5, 6],
            &[2, 1, 6, 7],
            &[3, 2, 7, 8],
            &[4, 3, 8, 9],
            &[0, 4, 9, 5],
            &[8, 7, 10, 11],
        ],
    )
}

/// Creases of [`mixed_mesh`]: semi-sharp 0.5, 1.5 and 2.3 on pentagon edges,
/// infinite (10 and 12) on the other two, and 1.0 on the spoke (1, 6).
pub fn mixed_creases() -> Vec<(u32, u32, f64)> {
    vec![
        (0, 1, 0.5),
        (1, 2, 1.5),
        (2, 3, 2.3),
        (3, 4, INFINITE),
        (4, 0, 12.0),
        (1, 6, 1.0),
    ]
}

/// Creases of [`mixed_mesh`] whose infinitely sharp edges form a path from
/// boundary to boundary (5–0–4–9), so no vertex ends up a dart (a single
/// infinitely sharp edge); semi-sharp 0.5, 1.5, 2.3 and 1.0 elsewhere.
pub fn mixed_creases_without_darts() -> Vec<(u32, u32, f64)> {
    vec![
        (0, 1, 0.5),
        (1, 2, 1.5),
        (2, 3, 2.3),
        (5, 0, INFINITE),
        (0, 4, 12.0),
        (4, 9, INFINITE),
        (1, 6, 1.0),
    ]
}

/// A closed pentagonal pyramid: a pentagon base and five triangles; the apex
/// (vertex 5) has valence 5, the base vertices valence 3.
pub fn pentagonal_pyramid() -> PolyMesh {
    let mut p: Vec<Point3> = (0..5)
        .map(|i| {
            let a = TAU * i as f64 / 5.0;
            Point3::new(a.cos() * (1.0 + 0.1 * i as f64), a.sin(), 0.05 * i as f64)
        })
        .collect();
    p.push(Point3::new(0.1, -0.05, 1.3));
    mesh(
        p,
        &[
            &[4, 3, 2, 1, 0],
            &[0, 1, 5],
            &[1, 2, 5],
            &[2, 3, 5],
            &[3, 4, 5],
            &[4, 0, 5],
        ],
    )
}

/// A closed triangular prism (two triangles, three quads), slightly skewed.
pub fn triangular_prism() -> PolyMesh {
    let p = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.1),
        Point3::new(0.4, 0.9, -0.05),
        Point3::new(0.05, 0.1, 1.2),
        Point3::new(1.1, 0.0, 1.0),
        Point3::new(0.5, 1.0, 1.1),
    ];
    mesh(
        p,
        &[
            &[0, 2, 1],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
    )
}

/// A single quad in the plane `z = 0` (slightly irregular shape).
pub fn single_quad() -> PolyMesh {
    mesh(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.2, 0.1, 0.0),
            Point3::new(1.0, 0.9, 0.0),
            Point3::new(-0.1, 1.1, 0.0),
        ],
        &[&[0, 1, 2, 3]],
    )
}

/// Index of grid vertex `(i, j)` in [`grid`] of `n` vertices per side.
pub fn grid_id(n: usize, i: usize, j: usize) -> u32 {
    (i * n + j) as u32
}

/// An `n × n`-vertex quad grid: vertex `(i, j)` near `(i, j, z)` with random
/// jitter in x, y and a random height; face `(i, j)` is
/// `[(i, j), (i+1, j), (i+1, j+1), (i, j+1)]`, so its `u` follows `i` and `v` follows `j`.
pub fn grid(n: usize, seed: u64) -> PolyMesh {
    let mut rng = Rng::new(seed);
    let mut p = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            p.push(Point3::new(
                i as f64 + rng.uniform(-0.2, 0.2),
                j as f64 + rng.uniform(-0.2, 0.2),
                rng.uniform(-0.5, 0.5),
            ));
        }
    }
    let faces: Vec<Vec<u32>> = (0..n - 1)
        .flat_map(|i| {
            (0..n - 1).map(move |j| {
                vec![
                    grid_id(n, i, j),
                    grid_id(n, i + 1, j),
                    grid_id(n, i + 1, j + 1),
                    grid_id(n, i, j + 1),
                ]
            })
        })
        .collect();
    PolyMesh::from_faces(p, &faces).expect("grid is valid")
}

/// The mesh with every vertex moved by a random vector of length ≤ `amount·√3`.
pub fn perturbed(mut mesh: PolyMesh, amount: f64, seed: u64) -> PolyMesh {
    let mut rng = Rng::new(seed);
    for p in &mut mesh.positions {
        *p += amount * rng.vector();
    }
    mesh
}

/// A refiner with the given boundary rule and creases.
pub fn refiner(mesh: &PolyMesh, boundary: BoundaryRule, creases: &[(u32, u32, f64)]) -> Refiner {
    Refiner::new(
        mesh,
        &RefineOptions {
            boundary,
            creases: creases.to_vec(),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("refiner: {e}"))
}

/// A refiner with default options (edge-and-corner, no creases).
pub fn default_refiner(mesh: &PolyMesh) -> Refiner {
    refiner(mesh, BoundaryRule::EdgeAndCorner, &[])
}

/// The cube refined `times` times uniformly (twice: 98 control points, 8 of
/// valence 3).
pub fn refined_cube(times: usize) -> PolyMesh {
    let mut mesh = subdyn::examples::cube();
    for _ in 0..times {
        let h = default_refiner(&mesh).refine_uniform(1).unwrap();
        let p = h.stencil(0).apply(&mesh.positions).unwrap();
        mesh = h.mesh(1, p);
    }
    mesh
}

/// Index at level `k` of the vertex point descending from level-0 vertex `v`
/// (vertex points come after face and edge points at every level).
pub fn descendant(h: &Hierarchy, k: usize, v: usize) -> usize {
    let mut idx = v;
    for l in 0..k {
        let lv = h.level(l);
        idx += lv.num_faces() + lv.num_edges();
    }
    idx
}

// ---------------------------------------------------------------------------
// Geometry

/// Bounding-box diagonal.
pub fn diag(points: &[Point3]) -> f64 {
    bbox_diagonal(points)
}

/// Largest `|a[i] − b[i]|` (same length required).
pub fn max_pairwise(a: &[Point3], b: &[Point3]) -> f64 {
    assert_eq!(a.len(), b.len(), "point lists differ in length");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// Largest distance from a point of `a` to its nearest neighbour in `b`.
pub fn max_nearest(a: &[Point3], b: &[Point3]) -> f64 {
    a.iter()
        .map(|x| {
            b.iter()
                .map(|y| (x - y).norm_squared())
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .fold(0.0, f64::max)
}

/// Symmetric point-set distance: the larger of both nearest-neighbour maxima.
pub fn point_set_distance(a: &[Point3], b: &[Point3]) -> f64 {
    max_nearest(a, b).max(max_nearest(b, a))
}

/// `A p + b` for every point.
pub fn affine(points: &[Point3], a: &nalgebra::Matrix3<f64>, b: &Vector3) -> Vec<Point3> {
    points
        .iter()
        .map(|p| Point3::from(a * p.coords + b))
        .collect()
}

/// A well-conditioned random affine map.
pub fn random_affine(rng: &mut Rng) -> (nalgebra::Matrix3<f64>, Vector3) {
    let mut a = nalgebra::Matrix3::identity() * 1.5;
    for i in 0..3 {
        for j in 0..3 {
            a[(i, j)] += rng.uniform(-0.7, 0.7);
        }
    }
    assert!(
        a.determinant().abs() > 0.1,
        "affine map too close to singular"
    );
    (a, 3.0 * rng.vector())
}

// ---------------------------------------------------------------------------
// Face parameterisation (quads: whole face; n-gons: quad sub-face tiles)

/// Tiles per row of an `n`-gon's parameter domain, `d = ⌈√n⌉`.
pub fn tiles_per_row(n: usize) -> usize {
    (n as f64).sqrt().ceil() as usize
}

/// Origin `(tu, tv)` of sub-face `i` of an `n`-gon (`n ≠ 4`).
pub fn tile_origin(n: usize, i: usize) -> (f64, f64) {
    let d = tiles_per_row(n);
    ((i % d) as f64, (i / d) as f64)
}

/// Parameters of corner `i` of a face with `n` vertices.
pub fn corner_param(n: usize, i: usize) -> (f64, f64) {
    if n == 4 {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)][i]
    } else {
        tile_origin(n, i)
    }
}

/// Parameters `eps` inside face-corner `i` of a face with `n` vertices
/// (diagonally into the quad, or into sub-face `i` of an n-gon).
pub fn near_corner_param(n: usize, i: usize, eps: f64) -> (f64, f64) {
    let (u, v) = corner_param(n, i);
    if n == 4 {
        let (su, sv) = ([1.0, -1.0, -1.0, 1.0][i], [1.0, 1.0, -1.0, -1.0][i]);
        (u + su * eps, v + sv * eps)
    } else {
        (u + eps, v + eps)
    }
}

/// Parameters of the point at fraction `tau ∈ [0, 1]` along edge `k` (from
/// face vertex `k` to `k + 1`) of a face with `n` vertices, and the
/// derivative `d(u, v)/dτ` there.
pub fn edge_param(n: usize, k: usize, tau: f64) -> ((f64, f64), (f64, f64)) {
    if n == 4 {
        let c = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let (a, b) = (c[k], c[(k + 1) % 4]);
        let d = (b.0 - a.0, b.1 - a.1);
        return ((a.0 + tau * d.0, a.1 + tau * d.1), d);
    }
    if tau <= 0.5 {
        // Sub-face k: s from corner k towards the midpoint of edge k.
        let (tu, tv) = tile_origin(n, k);
        ((tu + tau, tv), (1.0, 0.0))
    } else {
        // Sub-face k+1: t from corner k+1 towards the midpoint of edge k.
        let (tu, tv) = tile_origin(n, (k + 1) % n);
        ((tu, tv + (1.0 - tau)), (0.0, -1.0))
    }
}

/// Random parameters inside face `face` (size `n`), at least `margin` (in
/// sub-patch units: the whole quad, or one sub-face's `[0, ½]²`) away from
/// the edges of the quad or sub-face.
pub fn random_param(rng: &mut Rng, n: usize, margin: f64) -> (f64, f64) {
    if n == 4 {
        (
            rng.uniform(margin, 1.0 - margin),
            rng.uniform(margin, 1.0 - margin),
        )
    } else {
        let (tu, tv) = tile_origin(n, rng.below(n));
        (
            tu + 0.5 * rng.uniform(margin, 1.0 - margin),
            tv + 0.5 * rng.uniform(margin, 1.0 - margin),
        )
    }
}

// ---------------------------------------------------------------------------
// The binary

/// Runs the `subdyn` binary with `args` in `dir`.
pub fn run_subdyn(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the subdyn binary runs")
}

/// The names of the files in `dir`.
pub fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Asserts a clean failure: exit code 1, exactly one stderr line
/// `subdyn: error: …` containing every `needle` (case-insensitive), no panic
/// text, and no file in `dir` other than `inputs`.
pub fn assert_clean_failure(
    dir: &Path,
    out: &std::process::Output,
    needles: &[&str],
    inputs: &[&str],
) {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "panic text in: {err}");
    assert!(!err.contains("RUST_BACKTRACE"), "backtrace hint in: {err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "expected one stderr line, got: {err}");
    assert!(lines[0].starts_with("subdyn: error: "), "prefix: {err}");
    for needle in needles {
        assert!(
            err.to_lowercase().contains(&needle.to_lowercase()),
            "`{needle}` not in: {err}"
        );
    }
    let mut expected: Vec<String> = inputs.iter().map(|s| s.to_string()).collect();
    expected.sort();
    assert_eq!(files(dir), expected, "files left behind");
}

pub mod sdf;
pub mod volume;

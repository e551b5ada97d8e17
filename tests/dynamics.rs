//! Physics of dynamic Catmull-Clark surfaces: quadrature, mass, damping,
//! stiffness, conjugate gradients.

mod common;

use common::{default_refiner, reference_mesh};
use subdyn::dynamics::{
    MaterialParams, PcgParams, damping_matrix, gauss_legendre, mass_matrix, patch_damping_matrix,
    patch_matrices, patch_sample_rows, patch_samples, patch_stiffness_and_damping,
    patch_stiffness_matrix, pcg, quadrature, stiffness_and_damping_elements, stiffness_matrix,
};
use subdyn::limit::{LimitEvaluator, PatchTable, tessellate};
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;
use subdyn::stencil::StencilTable;

fn lcg(seed: &mut u64) -> Real {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*seed >> 11) as Real / (1u64 << 53) as Real
}

/// Dense copy of a square table.
fn dense(a: &StencilTable) -> Vec<Vec<Real>> {
    let n = a.num_rows();
    let mut m = vec![vec![0.0; a.num_cols]; n];
    for (r, row) in m.iter_mut().enumerate() {
        let (c, w) = a.row(r);
        for (&c, &w) in c.iter().zip(w) {
            row[c as usize] += w;
        }
    }
    m
}

fn quad_form(a: &StencilTable, x: &[Real]) -> Real {
    let ax = a.apply(x).unwrap();
    ax.iter().zip(x).map(|(a, b)| a * b).sum()
}

fn assert_symmetric(a: &StencilTable, what: &str) {
    let m = dense(a);
    let scale = m.iter().flatten().fold(0.0f64, |s, x| s.max(x.abs()));
    for (i, row) in m.iter().enumerate() {
        for (j, &x) in row.iter().enumerate().take(i) {
            assert!(
                (x - m[j][i]).abs() <= 1e-13 * scale,
                "{what} not symmetric at ({i}, {j})"
            );
        }
    }
}

/// A flat n × n grid of unit squares in the plane z = 0.
fn flat_grid(n: usize) -> PolyMesh {
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let positions = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| Point3::new(i as Real, j as Real, 0.0)))
        .collect();
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolyMesh::from_faces(positions, &faces).unwrap()
}

#[test]
fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
    for n in 1..=10 {
        let gl = gauss_legendre(n);
        assert_eq!(gl.len(), n);
        for k in 0..2 * n {
            let integral: Real = gl.iter().map(|(x, w)| w * x.powi(k as i32)).sum();
            assert!(
                (integral - 1.0 / (k as Real + 1.0)).abs() < 1e-14,
                "n {n}, x^{k}: {integral}"
            );
        }
    }
}

#[test]
fn patch_table_stencils_reproduce_evaluation() {
    for mesh in [subdyn::examples::cube(), reference_mesh("fan5_open")] {
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 2).unwrap();
        let lp = table.to_level().apply(&mesh.positions).unwrap();
        let mut seed = 7;
        for _ in 0..300 {
            let f = (lcg(&mut seed) * table.num_patches() as Real) as usize;
            let st = [lcg(&mut seed), lcg(&mut seed)];
            let e = table.eval(f, st).unwrap();
            let s = table.stencil(f, st);
            let q: Vec<_> = (0..6)
                .map(|k| {
                    s.cols
                        .iter()
                        .zip(&s.weights[k])
                        .map(|(&c, &w)| w * lp[c as usize].coords)
                        .sum::<subdyn::math::Vector3>()
                })
                .collect();
            assert!(
                (q[0] - e.p.coords).norm() < 1e-12,
                "position at patch {f} {st:?}"
            );
            for k in 0..5 {
                assert!(
                    (q[k + 1] - e.d[k]).norm() < 1e-9 * (1.0 + e.d[k].norm()),
                    "derivative {k} at patch {f} {st:?}"
                );
            }
        }
    }
}

#[test]
fn mass_matrix_is_spd_and_sums_to_mu_times_area() {
    let mu = 2.5;
    // Flat grid: the limit surface is the square [0, n]² exactly.
    let grid = flat_grid(4);
    let r = default_refiner(&grid);
    let table = PatchTable::new(&r, &grid.positions, 2).unwrap();
    let q = quadrature(&table, 4).unwrap();
    let lp = table.to_level().apply(&grid.positions).unwrap();
    let m = mass_matrix(&q, table.to_level(), Some(&lp), mu).unwrap();
    let total: Real = m.weights.iter().sum();
    assert!(
        (total - mu * 16.0).abs() < 1e-10,
        "flat grid: Σ M = {total}, want {}",
        mu * 16.0
    );
    // Parameter measure: Σ M = μ · (number of faces).
    let mp = mass_matrix(&q, table.to_level(), None, mu).unwrap();
    let total: Real = mp.weights.iter().sum();
    assert!((total - mu * 16.0).abs() < 1e-10);

    // Cube (valence-3 vertices everywhere): against the area of a fine tessellation.
    let cube = subdyn::examples::cube();
    let r = default_refiner(&cube);
    let table = PatchTable::new(&r, &cube.positions, 2).unwrap();
    let q = quadrature(&table, 4).unwrap();
    let lp = table.to_level().apply(&cube.positions).unwrap();
    let m = mass_matrix(&q, table.to_level(), Some(&lp), mu).unwrap();
    // Tessellation areas converge as O(h²): Richardson-extrapolate two rates.
    let tess_area = |k: usize| -> Real {
        let (tess, _) = tessellate(&r, &cube.positions, k).unwrap();
        tess.faces()
            .map(|f| {
                let p: Vec<_> = f.iter().map(|&v| tess.positions[v as usize]).collect();
                0.5 * ((p[1] - p[0]).cross(&(p[2] - p[0])).norm()
                    + (p[2] - p[0]).cross(&(p[3] - p[0])).norm())
            })
            .sum()
    };
    let area = (4.0 * tess_area(64) - tess_area(32)) / 3.0;
    let total: Real = m.weights.iter().sum();
    assert!(
        (total / (mu * area) - 1.0).abs() < 2e-5,
        "cube: Σ M = {total}, μ·area ≈ {}",
        mu * area
    );
    assert_symmetric(&m, "M");
    // The cube's own M is only semi-definite: the checkerboard pattern of its
    // 8 control points (+1 on one tetrahedron, −1 on the other) has a zero
    // limit surface (limit mask 9/24 − 3·4/24 + 3·1/24 = 0), so it is in the
    // null space. One level finer the map to the limit surface is injective.
    let checker: Vec<Real> = (0..8)
        .map(|i: u32| {
            if i.count_ones().is_multiple_of(2) {
                1.0
            } else {
                -1.0
            }
        })
        .collect();
    assert!(quad_form(&m, &checker).abs() < 1e-12);
    for mesh in [
        grid,
        reference_mesh("torus_regular"),
        reference_mesh("fan5_open"),
    ] {
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 2).unwrap();
        let q = quadrature(&table, 4).unwrap();
        let lp = table.to_level().apply(&mesh.positions).unwrap();
        let m = mass_matrix(&q, table.to_level(), Some(&lp), mu).unwrap();
        assert_symmetric(&m, "M");
        let mut x = vec![Point3::origin(); m.num_rows()];
        // Positive definite: CG on M converges from any right-hand side.
        let b: Vec<Point3> = (0..m.num_rows())
            .map(|i| Point3::new(1.0, i as Real, (i % 3) as Real))
            .collect();
        let report = pcg(&m, &b, &mut x, &PcgParams::default()).unwrap();
        assert!(report.converged, "{report:?}");
        let mut seed = 3;
        for _ in 0..20 {
            let x: Vec<Real> = (0..m.num_rows()).map(|_| lcg(&mut seed) - 0.5).collect();
            assert!(quad_form(&m, &x) > 0.0, "M must be positive definite");
        }
    }
}

#[test]
fn stiffness_is_psd_with_translations_in_its_null_space() {
    for mesh in [
        subdyn::examples::cube(),
        reference_mesh("fan5_open"),
        reference_mesh("grid4_open"),
    ] {
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 2).unwrap();
        let q = quadrature(&table, 4).unwrap();
        let k = stiffness_matrix(&q, table.to_level(), &MaterialParams::default()).unwrap();
        assert_symmetric(&k, "K");
        let ones = vec![1.0; k.num_rows()];
        let k1 = k.apply(&ones).unwrap();
        let scale = k.weights.iter().fold(0.0f64, |s, w| s.max(w.abs()));
        assert!(
            k1.iter()
                .all(|v| v.abs() < 1e-12 * scale * k.num_rows() as Real),
            "K·1 = {k1:?}"
        );
        let mut seed = 11;
        for _ in 0..20 {
            let x: Vec<Real> = (0..k.num_rows()).map(|_| lcg(&mut seed) - 0.5).collect();
            assert!(
                quad_form(&k, &x) >= -1e-12 * scale,
                "K must be positive semi-definite"
            );
        }
    }
}

/// On a mesh of regular patches, M (parameter measure) and K agree with a
/// brute-force 10 × 10 Gauss-Legendre quadrature of the exact evaluator's
/// stencils per base face.
#[test]
fn regular_patches_agree_with_brute_force_quadrature() {
    let mesh = reference_mesh("torus_regular");
    let r = default_refiner(&mesh);
    let table = PatchTable::new(&r, &mesh.positions, 1).unwrap();
    let q = quadrature(&table, 4).unwrap();
    let params = MaterialParams::default();
    let m = dense(&mass_matrix(&q, table.to_level(), None, params.mu).unwrap());
    let k = dense(&stiffness_matrix(&q, table.to_level(), &params).unwrap());
    let eval = LimitEvaluator::new(&r);
    let n = mesh.num_vertices();
    let mut mb = vec![vec![0.0; n]; n];
    let mut kb = vec![vec![0.0; n]; n];
    let gl = gauss_legendre(10);
    let coefficients = [
        params.alpha11,
        params.alpha22,
        params.beta11,
        params.beta12,
        params.beta22,
    ];
    for f in 0..mesh.num_faces() {
        for &(u, wu) in &gl {
            for &(v, wv) in &gl {
                let s = eval.stencil(f, u, v).unwrap();
                let w = wu * wv;
                for (i, &a) in s.cols.iter().enumerate() {
                    for (j, &b) in s.cols.iter().enumerate() {
                        mb[a as usize][b as usize] +=
                            params.mu * w * s.weights[0][i] * s.weights[0][j];
                        for (t, c) in coefficients.iter().enumerate() {
                            kb[a as usize][b as usize] +=
                                c * w * s.weights[t + 1][i] * s.weights[t + 1][j];
                        }
                    }
                }
            }
        }
    }
    let worst = |x: &Vec<Vec<Real>>, y: &Vec<Vec<Real>>| {
        x.iter()
            .flatten()
            .zip(y.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    assert!(worst(&m, &mb) < 1e-10, "M differs by {:e}", worst(&m, &mb));
    assert!(worst(&k, &kb) < 1e-10, "K differs by {:e}", worst(&k, &kb));
}

/// The cube refined twice, perturbed.
fn refined_cube() -> PolyMesh {
    let mut mesh = common::refined_cube(2);
    let mut seed = 3;
    for p in &mut mesh.positions {
        p.x += 0.02 * lcg(&mut seed);
        p.y += 0.02 * lcg(&mut seed);
    }
    mesh
}

/// [`refined_cube`] with every fifth face split locally.
fn locally_refined_cube() -> PolyMesh {
    let mesh = refined_cube();
    let h = default_refiner(&mesh).refine_uniform(1).unwrap();
    let marks: Vec<bool> = (0..mesh.num_faces()).map(|f| f % 5 == 0).collect();
    subdyn::subdivision::refine_marked(&mesh, h.level(0), h.stencil(0), &marks)
        .unwrap()
        .mesh
}

/// The patch-by-patch element assembly gives the same matrices as the Gram
/// matrices of the sample rows at the same points: on regular patches the
/// exact ones of `quadrature`, at irregular vertices, boundaries and n-gons
/// those of `patch_samples`.
#[test]
fn element_assembly_matches_sample_gram_matrices() {
    let params = MaterialParams::default();
    for (mesh, exact) in [
        (reference_mesh("torus_regular"), true),
        (subdyn::examples::cube(), false),
        (reference_mesh("fan5_open"), false),
        (reference_mesh("grid4_open"), false),
        // Irregular patches of one structure many times over (their
        // elements are computed once and reordered): the eight corners of
        // a refined cube, and the T-vertices and pentagons of a locally
        // refined one.
        (refined_cube(), false),
        (locally_refined_cube(), false),
    ] {
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 1).unwrap();
        let q = if exact {
            quadrature(&table, 4).unwrap()
        } else {
            patch_samples(&table, 4).unwrap()
        };
        let s = table.to_level();
        let pairs = [
            (
                stiffness_matrix(&q, s, &params).unwrap(),
                patch_stiffness_matrix(&table, 4, &params).unwrap(),
            ),
            (
                damping_matrix(&q, s, None, 0.7).unwrap(),
                patch_damping_matrix(&table, 4, 0.7).unwrap(),
            ),
        ];
        for (reference, assembled) in pairs {
            let (a, b) = (dense(&reference), dense(&assembled));
            let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            let worst = a
                .iter()
                .flatten()
                .zip(b.iter().flatten())
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(
                scale > 0.0 && worst <= 1e-12 * scale,
                "element assembly differs by {worst:e} (scale {scale:e})"
            );
        }
    }
}

#[test]
fn pcg_solves_spd_systems_and_reports() {
    let mesh = reference_mesh("fan5_open");
    let r = default_refiner(&mesh);
    let table = PatchTable::new(&r, &mesh.positions, 2).unwrap();
    let q = quadrature(&table, 4).unwrap();
    let m = mass_matrix(&q, table.to_level(), None, 1.0).unwrap();
    let k = stiffness_matrix(&q, table.to_level(), &MaterialParams::default()).unwrap();
    let a = m.linear_combination(1.0, &k, 10.0).unwrap();
    let truth: Vec<Point3> = (0..a.num_rows())
        .map(|i| Point3::new(i as Real, 1.0, -(i as Real).sqrt()))
        .collect();
    let b = a.apply(&truth).unwrap();
    let mut x = vec![Point3::origin(); a.num_rows()];
    let report = pcg(&a, &b, &mut x, &PcgParams::default()).unwrap();
    assert!(report.converged, "{report:?}");
    assert!(report.iterations > 0 && report.iterations <= 10 * a.num_rows());
    for (x, t) in x.iter().zip(&truth) {
        assert!((x - t).norm() < 1e-8, "{x} vs {t}");
    }
    // The coordinates are independent solves run in lockstep: each takes
    // exactly the iterates of a solve of its own (the other coordinates
    // zero), and the report gives the slowest one's iterations.
    let mixed: Vec<Point3> = b
        .iter()
        .map(|p| Point3::new(p.x, 0.0, 1e-3 * p.z))
        .collect();
    let mut together = vec![Point3::origin(); a.num_rows()];
    let report = pcg(&a, &mixed, &mut together, &PcgParams::default()).unwrap();
    let mut slowest = 0;
    for k in 0..3 {
        let alone: Vec<Point3> = mixed
            .iter()
            .map(|p| {
                let mut q = Point3::origin();
                q[k] = p[k];
                q
            })
            .collect();
        let mut xk = vec![Point3::origin(); a.num_rows()];
        slowest = slowest.max(
            pcg(&a, &alone, &mut xk, &PcgParams::default())
                .unwrap()
                .iterations,
        );
        assert!(
            together.iter().zip(&xk).all(|(t, s)| t[k] == s[k]),
            "coordinate {k}"
        );
    }
    assert_eq!(report.iterations, slowest);
    // K alone is singular (translations): its diagonal is positive but CG on
    // an inconsistent system must not claim convergence silently.
    assert!(
        pcg(
            &StencilTable::zeros(3, 3),
            &[Point3::origin(); 3],
            &mut [Point3::origin(); 3],
            &PcgParams::default()
        )
        .is_err()
    );
}

/// Largest entry-wise difference of two tables with the same rows, and the
/// largest entry of the first.
fn table_difference(a: &StencilTable, b: &StencilTable) -> (Real, Real) {
    assert_eq!(a.num_rows(), b.num_rows());
    assert_eq!(a.num_cols, b.num_cols);
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    let mut row = vec![0.0; a.num_cols];
    for r in 0..a.num_rows() {
        let ((ca, wa), (cb, wb)) = (a.row(r), b.row(r));
        for (&c, &w) in ca.iter().zip(wa) {
            row[c as usize] += w;
            scale = scale.max(w.abs());
        }
        for (&c, &w) in cb.iter().zip(wb) {
            row[c as usize] -= w;
        }
        for x in row.iter_mut() {
            worst = worst.max(x.abs());
            *x = 0.0;
        }
    }
    (worst, scale)
}

/// The tangent rows composed patch by patch equal `patch_samples`'
/// level-`L` rows composed afterwards, on meshes with irregular vertices,
/// boundaries and n-gons; they annihilate constants, and the weights sum
/// to the base faces' area.
#[test]
fn sample_rows_equal_the_composed_patch_samples() {
    for mesh in [
        subdyn::examples::cube(),
        reference_mesh("fan5_open"),
        common::mixed_mesh(),
    ] {
        let r = default_refiner(&mesh);
        let table = PatchTable::new(&r, &mesh.positions, 1).unwrap();
        let rows = patch_sample_rows(&table, 3).unwrap();
        let q = patch_samples(&table, 3).unwrap();
        let s = table.to_level();
        for (a, b, name) in [(&q.rows.du, &rows.ju, "J_u"), (&q.rows.dv, &rows.jv, "J_v")] {
            let (worst, scale) = table_difference(&a.compose(s).unwrap(), b);
            assert!(
                scale > 0.0 && worst <= 1e-13 * scale,
                "{name}: differs by {worst:e} (largest entry {scale:e})"
            );
        }
        assert_eq!(rows.weights, q.weights);
        assert_eq!(rows.patch, q.patch);
        for t in [&rows.ju, &rows.jv] {
            for (r, sum) in t.row_sums().iter().enumerate() {
                assert!(sum.abs() < 1e-12, "row {r} sums to {sum}");
            }
        }
        // The base faces' parameter area: every patch covers |det(axes)| of it.
        let area: Real = (0..table.num_patches())
            .map(|f| {
                let a = table.patch_frame(f).1;
                (a[0][0] * a[1][1] - a[0][1] * a[1][0]).abs()
            })
            .sum();
        let total: Real = rows.weights.iter().sum();
        assert!((total - area).abs() < 1e-12 * area, "{total} vs {area}");
        assert!(patch_sample_rows(&table, 0).is_err());
    }
}

/// `PatchTable::stencils` (a batch; an irregular patch's quadtree built for
/// the call alone) gives exactly the stencils of `stencil` (which caches
/// the quadtree), and the same again once the quadtree is cached.
#[test]
fn batched_stencils_equal_single_stencils() {
    let mesh = common::mixed_mesh();
    let r = default_refiner(&mesh);
    let table = PatchTable::new(&r, &mesh.positions, 1).unwrap();
    let sts = [[0.1, 0.2], [0.5, 0.5], [0.9, 0.03], [0.0, 0.0], [1.0, 0.7]];
    for f in 0..table.num_patches() {
        let batch = table.stencils(f, &sts);
        let single: Vec<_> = sts.iter().map(|&st| table.stencil(f, st)).collect();
        let cached = table.stencils(f, &sts);
        for ((a, b), c) in batch.iter().zip(&single).zip(&cached) {
            assert_eq!(a.cols, b.cols, "patch {f}");
            assert_eq!(a.weights, b.weights, "patch {f}");
            assert_eq!(c.cols, b.cols, "patch {f}");
            assert_eq!(c.weights, b.weights, "patch {f}");
        }
    }
}

/// `K` and `D` assembled in one pass equal the matrices assembled apart.
#[test]
fn stiffness_and_damping_in_one_pass_equal_the_separate_matrices() {
    let params = MaterialParams::default();
    let mesh = subdyn::examples::cube();
    let table = PatchTable::new(&default_refiner(&mesh), &mesh.positions, 1).unwrap();
    let [k, d] = patch_stiffness_and_damping(&table, 4, &params, 0.3).unwrap();
    for (together, apart) in [
        (k, patch_stiffness_matrix(&table, 4, &params).unwrap()),
        (d, patch_damping_matrix(&table, 4, 0.3).unwrap()),
    ] {
        let (worst, scale) = table_difference(&together, &apart);
        assert!(
            scale > 0.0 && worst <= 1e-14 * scale,
            "{worst:e} of {scale:e}"
        );
    }
    assert!(patch_stiffness_and_damping(&table, 4, &params, -1.0).is_err());
}

/// Springs assembled into the patches' fixed pattern equal the sparse
/// products `Σ k JᵀJ`, `Σ k Jᵀ d` of `spring_system` / `row_springs`, on
/// meshes with irregular vertices, boundaries and n-gons; `K` carried into
/// the pattern is unchanged; a matrix outside the pattern is refused.
#[test]
fn patch_assembly_equals_the_sparse_spring_products() {
    use subdyn::forces::{PatchAssembly, RowSprings, row_springs, spring_system};
    use subdyn::limit::{ClosestPointEngine, ClosestPointParams};
    let mut seed = 7u64;
    for mesh in [
        subdyn::examples::cube(),
        reference_mesh("fan5_open"),
        common::mixed_mesh(),
    ] {
        let r = default_refiner(&mesh);
        let engine = ClosestPointEngine::new(
            &r,
            &mesh.positions,
            &ClosestPointParams {
                level: 1,
                ..Default::default()
            },
        )
        .unwrap();
        let table = engine.table();
        let assembly = PatchAssembly::new(table).unwrap();
        let scale = common::diag(&mesh.positions);
        let points: Vec<Point3> = (0..300)
            .map(|i| {
                let v = mesh.positions[i % mesh.positions.len()];
                v + scale
                    * 0.3
                    * nalgebra::Vector3::new(lcg(&mut seed), lcg(&mut seed), lcg(&mut seed))
            })
            .collect();
        let closest = engine.closest_points(&points).unwrap();
        let k: Vec<Real> = (0..points.len())
            .map(|i| if i % 7 == 0 { 0.0 } else { lcg(&mut seed) })
            .collect();
        let data_reference = spring_system(&engine, &points, &closest, &k).unwrap();
        let reference = data_reference.clone();
        let fast = assembly
            .data_springs(table, &points, &closest, &k, None)
            .unwrap();
        let (worst, m) = table_difference(&reference.matrix, &fast.matrix);
        assert!(m > 0.0 && worst <= 1e-12 * m, "matrix {worst:e} of {m:e}");
        for (a, b) in reference.rhs.iter().zip(&fast.rhs) {
            assert!((a - b).norm() <= 1e-12 * scale, "rhs {a} vs {b}");
        }
        assert!((reference.energy - fast.energy).abs() <= 1e-12 * reference.energy);

        // Rows already over the control points (as the surface samples are).
        let s = table.to_level();
        // Inside the patches, and at every patch's corners (at an irregular
        // vertex itself the quadtree gives way to exact evaluation).
        let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        let at: Vec<(usize, [Real; 2])> = (0..200)
            .map(|i| (i % table.num_patches(), [lcg(&mut seed), lcg(&mut seed)]))
            .chain((0..table.num_patches()).flat_map(|f| corners.map(|st| (f, st))))
            .collect();
        let mut rows = StencilTable::with_capacity(s.num_rows(), at.len(), 0);
        for &(f, st) in &at {
            let (c, w) = table.position_stencil(f, st);
            rows.push_row(c.into_iter().zip(w));
        }
        let rows = rows.compose(s).unwrap();
        let x = rows.apply(&mesh.positions).unwrap();
        let d: Vec<Point3> = x
            .iter()
            .map(|p| p + nalgebra::Vector3::new(0.1, -0.2, 0.05))
            .collect();
        let kr: Vec<Real> = (0..at.len()).map(|_| lcg(&mut seed)).collect();
        let reference = row_springs(&rows, &x, &d, &kr).unwrap();
        let on_patches = assembly.rows_at(table, &at).unwrap();
        let (worst, m) = table_difference(&rows, on_patches.rows());
        assert!(
            m > 0.0 && worst <= 1e-12 * m,
            "rows on patches {worst:e} of {m:e}"
        );
        let fast = assembly.row_springs(&on_patches, &x, &d, &kr).unwrap();
        let (worst, m) = table_difference(&reference.matrix, &fast.matrix);
        assert!(
            m > 0.0 && worst <= 1e-12 * m,
            "row matrix {worst:e} of {m:e}"
        );
        // Both kinds in one pass: the sum of the two systems.
        let both = assembly
            .data_springs(
                table,
                &points,
                &closest,
                &k,
                Some(RowSprings {
                    rows: &on_patches,
                    x: &x,
                    d: &d,
                    k: &kr,
                }),
            )
            .unwrap();
        let mut sum = data_reference;
        sum.add(&reference).unwrap();
        let (worst, m) = table_difference(&sum.matrix, &both.matrix);
        assert!(
            m > 0.0 && worst <= 1e-12 * m,
            "summed matrix {worst:e} of {m:e}"
        );
        for (a, b) in sum.rhs.iter().zip(&both.rhs) {
            assert!((a - b).norm() <= 1e-12 * scale, "summed rhs {a} vs {b}");
        }
        assert!((sum.energy - both.energy).abs() <= 1e-12 * sum.energy);
        let short = RowSprings {
            rows: &on_patches,
            x: &x[1..],
            d: &d,
            k: &kr,
        };
        assert!(
            assembly
                .data_springs(table, &points, &closest, &k, Some(short))
                .is_err()
        );
        let stiffness = patch_stiffness_matrix(table, 4, &MaterialParams::default()).unwrap();
        let carried = assembly.matrix(assembly.values_of(&stiffness).unwrap());
        let (worst, m) = table_difference(&stiffness, &carried);
        assert!(worst <= 1e-15 * m, "K in the pattern {worst:e} of {m:e}");
        // The elements carried patch by patch equal the sparse `Sᵀ K_L S`.
        let params = MaterialParams::default();
        let elements = stiffness_and_damping_elements(table, 4, &params, 0.3).unwrap();
        let reference = patch_stiffness_and_damping(table, 4, &params, 0.3).unwrap();
        let carried = assembly
            .values_of_elements(table, |f| elements.get(f))
            .unwrap();
        for (i, (reference, values)) in reference.iter().zip(carried).enumerate() {
            let (worst, m) = table_difference(reference, &assembly.matrix(values));
            assert!(
                m > 0.0 && worst <= 1e-12 * m,
                "element {i}: {worst:e} of {m:e}"
            );
        }
    }
    // On a 6 × 6 grid, the corners share no patch: a dense matrix is refused.
    let grid = common::grid(6, 1);
    let table = PatchTable::new(&default_refiner(&grid), &grid.positions, 1).unwrap();
    let assembly = PatchAssembly::new(&table).unwrap();
    let n = grid.positions.len();
    let full = StencilTable::from_rows(n, &vec![(0..n as u32).map(|c| (c, 1.0)).collect(); n]);
    assert!(assembly.values_of(&full).is_err());
    assert!(assembly.num_entries() < n * n);
    // A row on a patch out of range is refused.
    let last = table.num_patches() - 1;
    let on_last = assembly.rows_at(&table, &[(last, [0.5, 0.5])]).unwrap();
    let x = on_last.rows().apply(&grid.positions).unwrap();
    assert!(assembly.row_springs(&on_last, &x, &x, &[1.0]).is_ok());
    assert!(assembly.rows_at(&table, &[(last + 1, [0.5, 0.5])]).is_err());
}

/// Materials per base face: one material for every face gives the
/// constant-material matrices; `M` sums to `Σ_f μ_f` (each quad face has
/// parameter area 1 and the basis sums to 1); the matrices add over a split
/// of the faces; a face's bad material is named.
#[test]
fn materials_per_face() {
    let mesh = refined_cube();
    let faces = mesh.num_faces();
    let table = PatchTable::new(&default_refiner(&mesh), &mesh.positions, 1).unwrap();
    let worst = |a: &StencilTable, b: &StencilTable| {
        let (a, b) = (dense(a), dense(b));
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, Real::max)
    };
    let one = MaterialParams::default();
    let [m, d, k] = patch_matrices(&table, 4, &[one]).unwrap();
    assert!(worst(&m, &patch_damping_matrix(&table, 4, one.mu).unwrap()) < 1e-13);
    assert!(worst(&d, &patch_damping_matrix(&table, 4, one.gamma).unwrap()) < 1e-13);
    assert!(worst(&k, &patch_stiffness_matrix(&table, 4, &one).unwrap()) < 1e-13);

    let per: Vec<MaterialParams> = (0..faces)
        .map(|f| MaterialParams {
            mu: 1.0 + 0.1 * f as Real,
            alpha11: 0.01 * (f % 2) as Real,
            beta22: 0.001 * (1 + f % 5) as Real,
            ..one
        })
        .collect();
    let [mp, dp, kp] = patch_matrices(&table, 4, &per).unwrap();
    let total: Real = mp.weights.iter().sum();
    let expected: Real = per.iter().map(|m| m.mu).sum();
    assert!(
        (total - expected).abs() < 1e-10 * expected,
        "{total} vs {expected}"
    );
    assert!(worst(&dp, &d) < 1e-13, "γ is the same on every face");
    assert!(worst(&kp, &k) > 1e-4, "the faces' elasticities must show");
    assert_symmetric(&kp, "per-face K");

    let zero = MaterialParams {
        mu: 0.0,
        gamma: 0.0,
        alpha11: 0.0,
        alpha22: 0.0,
        beta11: 0.0,
        beta12: 0.0,
        beta22: 0.0,
    };
    let half = |even: bool| -> Vec<MaterialParams> {
        (0..faces)
            .map(|f| if (f % 2 == 0) == even { per[f] } else { zero })
            .collect()
    };
    let [ma, _, ka] = patch_matrices(&table, 4, &half(true)).unwrap();
    let [mb, _, kb] = patch_matrices(&table, 4, &half(false)).unwrap();
    let sum = |a: &StencilTable, b: &StencilTable| a.linear_combination(1.0, b, 1.0).unwrap();
    assert!(worst(&sum(&ma, &mb), &mp) < 1e-13);
    assert!(worst(&sum(&ka, &kb), &kp) < 1e-13);

    let err = patch_matrices(&table, 4, &per[1..])
        .unwrap_err()
        .to_string();
    assert!(err.contains("one per face"), "{err}");
    let mut bad = per.clone();
    bad[5].beta11 = -1.0;
    let err = patch_matrices(&table, 4, &bad).unwrap_err().to_string();
    assert!(err.contains("face 5") && err.contains("beta11"), "{err}");
}

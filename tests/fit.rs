//! Fitting point clouds with dynamic Catmull-Clark surfaces.

use subdyn::fit::{FitParams, Refinement, fit_point_cloud};
use subdyn::forces::RobustKernel;
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::subdivision::{RefineOptions, Refiner};

struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as Real / (1u64 << 53) as Real
    }
    fn gauss(&mut self) -> Real {
        (-2.0 * self.uniform().max(1e-300).ln()).sqrt()
            * (std::f64::consts::TAU * self.uniform()).cos()
    }
}

/// `n` points on the unit sphere, with Gaussian noise of `sigma` along the radius.
fn sphere_scan(n: usize, sigma: Real, seed: u64) -> PointCloud {
    let mut rng = Rng(seed);
    let pts = (0..n)
        .map(|_| {
            let z = 2.0 * rng.uniform() - 1.0;
            let t = std::f64::consts::TAU * rng.uniform();
            let r = (1.0 - z * z).sqrt();
            Point3::from(Vector3::new(r * t.cos(), r * t.sin(), z) * (1.0 + sigma * rng.gauss()))
        })
        .collect();
    PointCloud::new(pts, None).unwrap()
}

/// The cube [-1, 1]³ as a control mesh.
fn cube_cage() -> PolyMesh {
    let mut cube = subdyn::examples::cube();
    for p in &mut cube.positions {
        *p = Point3::from((p.coords - Vector3::new(0.5, 0.5, 0.5)) * 2.0);
    }
    cube
}

/// Largest and mean distance of a dense limit tessellation to the unit sphere.
fn sphere_deviation(control: &PolyMesh) -> (Real, Real) {
    let r = Refiner::new(control, &RefineOptions::default()).unwrap();
    let (tess, _) = tessellate(&r, &control.positions, 4).unwrap();
    let d: Vec<Real> = tess
        .positions
        .iter()
        .map(|p| (p.coords.norm() - 1.0).abs())
        .collect();
    (
        d.iter().cloned().fold(0.0, f64::max),
        d.iter().sum::<Real>() / d.len() as Real,
    )
}

/// The first-order (massless) dynamics and the paper's second-order ones
/// (with mass) both fit a noisy sphere below the noise.
#[test]
fn noisy_sphere_fits_below_the_noise_level() {
    for mass in [0.0, 0.5] {
        noisy_sphere_fit(mass);
    }
}

fn noisy_sphere_fit(mass: Real) {
    let diag = 2.0 * 3f64.sqrt();
    let sigma = 0.001 * diag; // 0.1 % of the diagonal
    let cloud = sphere_scan(6000, sigma, 1);
    let params = FitParams {
        mass,
        ..Default::default()
    };
    let result = fit_point_cloud(&cloud, &cube_cage(), &params, &mut |_, _, _| {}).unwrap();
    let (max, mean) = sphere_deviation(&result.control);
    assert!(
        mean < sigma,
        "mass {mass}: mean deviation {mean:e} vs noise {sigma:e}"
    );
    assert!(max < 0.01 * diag, "mass {mass}: max deviation {max:e}");
    let report = &result.report;
    assert!(
        report.levels.len() >= 2,
        "the fit must subdivide at least once"
    );
    for w in report.levels.windows(2) {
        assert!(w[1].control_points > w[0].control_points);
        assert!(
            w[1].error.rms <= w[0].error.rms * 1.01,
            "RMS error must not grow with the level"
        );
    }
}

#[test]
fn energy_decreases_monotonically_without_robust_reweighting() {
    let cloud = sphere_scan(2000, 0.0, 2);
    let params = FitParams {
        robust: RobustKernel::None,
        max_level: 1,
        max_steps: 12,
        energy_tolerance: 0.0,
        error_tolerance: 0.0,
        ..Default::default()
    };
    let result = fit_point_cloud(&cloud, &cube_cage(), &params, &mut |_, _, _| {}).unwrap();
    for level in &result.report.levels {
        for w in level.energy.windows(2) {
            assert!(
                w[1] <= w[0] * (1.0 + 1e-12),
                "level {}: energy rose {:?}",
                level.level,
                level.energy
            );
        }
    }
}

#[test]
fn outliers_do_not_pull_the_surface() {
    let diag = 2.0 * 3f64.sqrt();
    let mut cloud = sphere_scan(4000, 0.0005 * diag, 3);
    let mut rng = Rng(99);
    for _ in 0..200 {
        // 5 % outliers, uniform in the bounding box enlarged by half.
        let p = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 3.0
            - Vector3::new(1.5, 1.5, 1.5);
        cloud.positions.push(Point3::from(p));
    }
    let fit = |params: &FitParams| {
        let result = fit_point_cloud(&cloud, &cube_cage(), params, &mut |_, _, _| {}).unwrap();
        let (_, mean) = sphere_deviation(&result.control);
        assert!(
            mean < 0.002 * diag,
            "mean deviation {mean:e} with 5 % outliers ({:?})",
            params.robust
        );
        result
    };
    // By default most of them are flagged before the fit and left out of
    // the springs (some uniform outliers land within the noise of the
    // sphere), and Huber springs fit the rest.
    let result = fit(&FitParams::default());
    assert!(
        (150..=210).contains(&result.report.outliers),
        "{} points left out as outliers, 200 planted",
        result.report.outliers
    );
    // Without that filter, Tukey's kernel rejects them during the fit.
    let result = fit(&FitParams {
        drop_outliers: false,
        robust: RobustKernel::Tukey(4.685),
        ..Default::default()
    });
    assert_eq!(result.report.outliers, 0);
    assert!(
        result.report.levels.last().unwrap().rejected > 0.02,
        "outliers must be rejected"
    );
}

/// The stop rules judge the points kept in the springs: 5 % outliers, whose
/// distances are the 95th percentile of all points, do not drive the fit to
/// its last level.
#[test]
fn outliers_do_not_decide_the_levels() {
    let diag = 2.0 * 3f64.sqrt();
    let clean = sphere_scan(4000, 0.001 * diag, 5);
    let mut noisy = clean.clone();
    let mut rng = Rng(7);
    for _ in 0..200 {
        let p = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 3.0
            - Vector3::new(1.5, 1.5, 1.5);
        noisy.positions.push(Point3::from(p));
    }
    let params = FitParams {
        max_level: 3,
        ..Default::default()
    };
    let fit = |cloud: &PointCloud| {
        fit_point_cloud(cloud, &cube_cage(), &params, &mut |_, _, _| {})
            .unwrap()
            .report
    };
    let (a, b) = (fit(&clean), fit(&noisy));
    assert!(
        a.levels.len() <= 3,
        "the clean sphere took {} levels",
        a.levels.len()
    );
    assert_eq!(
        a.levels.len(),
        b.levels.len(),
        "levels without and with outliers (stops: {:?} / {:?})",
        a.stop_reason,
        b.stop_reason
    );
    let (kept, all) = (
        b.levels.last().unwrap().kept_error,
        b.levels.last().unwrap().error,
    );
    assert!(
        all.p95_pct > 1.2 * kept.p95_pct,
        "p95 of all points {} %, of the kept {} %",
        all.p95_pct,
        kept.p95_pct
    );
}

#[test]
fn bad_inputs_are_errors() {
    let cage = cube_cage();
    let empty = PointCloud::default();
    assert!(fit_point_cloud(&empty, &cage, &FitParams::default(), &mut |_, _, _| {}).is_err());
    let three = PointCloud::new(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        None,
    )
    .unwrap();
    let e = fit_point_cloud(&three, &cage, &FitParams::default(), &mut |_, _, _| {}).unwrap_err();
    assert!(e.to_string().contains("3 points"), "{e}");
    let same = PointCloud::new(vec![Point3::new(1.0, 2.0, 3.0); 20], None).unwrap();
    assert!(fit_point_cloud(&same, &cage, &FitParams::default(), &mut |_, _, _| {}).is_err());
    // A non-manifold initial mesh: three quads sharing one edge.
    let p = |x: Real, y: Real, z: Real| Point3::new(x, y, z);
    let fin = PolyMesh::from_faces(
        vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, -1.0, 0.0),
            p(1.0, -1.0, 0.0),
            p(0.0, 0.0, 1.0),
            p(1.0, 0.0, 1.0),
        ],
        &[vec![0, 1, 3, 2], vec![1, 0, 4, 5], vec![0, 1, 7, 6]],
    )
    .unwrap();
    let e = fit_point_cloud(
        &sphere_scan(100, 0.0, 4),
        &fin,
        &FitParams::default(),
        &mut |_, _, _| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("non-manifold"), "{e}");
    let bad = FitParams {
        tolerance_pct: -1.0,
        ..Default::default()
    };
    assert!(fit_point_cloud(&sphere_scan(100, 0.0, 5), &cage, &bad, &mut |_, _, _| {}).is_err());
}

/// A unit sphere with a narrow bump of height 0.25 around +z, scanned with
/// noise along the radius.
fn bumpy_sphere_scan(n: usize, sigma: Real) -> PointCloud {
    let mut cloud = sphere_scan(n, 0.0, 9);
    let mut rng = Rng(10);
    for p in &mut cloud.positions {
        let dir = p.coords.normalize();
        let angle = dir.z.clamp(-1.0, 1.0).acos();
        let bump = 0.25 * (-(angle / 0.3).powi(2)).exp();
        *p = Point3::from(dir * (1.0 + bump + sigma * rng.gauss()));
    }
    cloud
}

/// Adaptive refinement on a sphere with a narrow bump, from a 98-point cage:
/// every level either splits some faces or, when that fitted worse than its
/// parent (transitions next to the bump can cost more than the split faces
/// gain), refines the parent uniformly instead.
/// Either way no level ends worse than its parent, and the result is as
/// good as uniform refinement's for no more control points, or better.
#[test]
fn adaptive_levels_never_end_worse_than_their_parents() {
    let cloud = bumpy_sphere_scan(12_000, 0.002);
    // The cube cage refined twice, on the sphere: 98 control points.
    let mut cage = cube_cage();
    for _ in 0..2 {
        let h = Refiner::new(&cage, &RefineOptions::default())
            .unwrap()
            .refine_uniform(1)
            .unwrap();
        let p = h.stencil(0).apply(&cage.positions).unwrap();
        cage = h.mesh(1, p);
    }
    for p in &mut cage.positions {
        *p = Point3::from(p.coords.normalize());
    }
    let fit = |refinement| {
        let params = FitParams {
            refinement,
            max_level: 2,
            tolerance_pct: 0.01,
            ..Default::default()
        };
        fit_point_cloud(&cloud, &cage, &params, &mut |_, _, _| {}).unwrap()
    };
    let adaptive = fit(Refinement::Adaptive);
    let uniform = fit(Refinement::Uniform);
    let levels = &adaptive.report.levels;
    assert!(levels.len() >= 2);
    assert_eq!(levels[0].refinement, "initial");
    for w in levels.windows(2) {
        let how = &w[1].refinement;
        assert!(
            how.starts_with("adaptive: ") || how.starts_with("uniform, after an adaptive level"),
            "{how}"
        );
        // A kept adaptive level is not worse on both statistics.
        assert!(
            w[1].error.p95 <= w[0].error.p95 || w[1].error.rms <= w[0].error.rms,
            "level {} ({how}) is worse than its parent",
            w[1].level
        );
    }
    let (a, u) = (
        levels.last().unwrap(),
        uniform.report.levels.last().unwrap(),
    );
    // Not dominated by uniform refinement: more control points only for a
    // lower error (the adaptive fit may go a level deeper than the uniform
    // one, whose finer level is already within the noise).
    assert!(
        a.control_points <= u.control_points || a.error.rms < u.error.rms,
        "adaptive {} control points, RMS {}; uniform {}, RMS {}",
        a.control_points,
        a.error.rms,
        u.control_points,
        u.error.rms
    );
    assert!(
        a.error.rms < 1.1 * u.error.rms,
        "RMS adaptive {} uniform {}",
        a.error.rms,
        u.error.rms
    );
}

/// The initial model's outlier screening, handed to the fit, gives the same
/// fit as screening again; a screening of another cloud is refused.
#[test]
fn the_initial_models_screening_serves_the_fit() {
    use subdyn::fit::fit_screened_cloud;
    use subdyn::fit::init::{InitParams, initial_mesh};
    let mut cloud = sphere_scan(3000, 0.002, 5);
    // A few far points for the screening to drop.
    cloud.positions.extend([
        Point3::new(3.0, 0.0, 0.0),
        Point3::new(0.0, -2.5, 1.0),
        Point3::new(1.5, 1.5, 1.5),
    ]);
    let (init, report) = initial_mesh(&cloud, &InitParams::default()).unwrap();
    let screening = report.screening.expect("an unthinned cloud's screening");
    assert_eq!(screening.keep.len(), cloud.len());
    assert_eq!(screening.keep.iter().filter(|&&k| !k).count(), 3);
    let params = FitParams {
        max_level: 1,
        ..Default::default()
    };
    let again = fit_point_cloud(&cloud, &init, &params, &mut |_, _, _| {}).unwrap();
    let reused =
        fit_screened_cloud(&cloud, Some(&screening), &init, &params, &mut |_, _, _| {}).unwrap();
    assert_eq!(again.control.positions, reused.control.positions);
    assert_eq!(again.report.outliers, 3);
    assert_eq!(reused.report.outliers, 3);
    let mut other = screening.clone();
    other.keep.pop();
    let err = fit_screened_cloud(&cloud, Some(&other), &init, &params, &mut |_, _, _| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("screening of 3002 points for a cloud of 3003"),
        "{err}"
    );
}

/// `n` points, area-uniform, on a unit sphere with a thin horn: a cone of
/// base radius 0.12 on the sphere at +z and apex at z = 2.2 (the union's
/// surface), with Gaussian noise of `sigma` along the normal.
fn horned_sphere_scan(n: usize, sigma: Real, seed: u64) -> PointCloud {
    let (base_r, apex) = (0.12, 2.2);
    let base_z = (1.0 - base_r * base_r as Real).sqrt();
    let slant = (base_r * base_r + (apex - base_z) * (apex - base_z)).sqrt();
    let horn_area = std::f64::consts::PI * base_r * slant;
    let sphere_area = 4.0 * std::f64::consts::PI;
    let mut rng = Rng(seed);
    let mut pts = Vec::with_capacity(n);
    while pts.len() < n {
        if rng.uniform() * (sphere_area + horn_area) < sphere_area {
            let z = 2.0 * rng.uniform() - 1.0;
            if z > base_z {
                continue; // inside the horn's base
            }
            let t = std::f64::consts::TAU * rng.uniform();
            let r = (1.0 - z * z).sqrt();
            let p = Vector3::new(r * t.cos(), r * t.sin(), z);
            pts.push(Point3::from(p * (1.0 + sigma * rng.gauss())));
        } else {
            // Area-uniform on the cone: the distance from the apex is
            // distributed as sqrt(u).
            let s = rng.uniform().sqrt();
            let t = std::f64::consts::TAU * rng.uniform();
            let (r, z) = (s * base_r, apex - s * (apex - base_z));
            let normal = Vector3::new(t.cos() * (apex - base_z), t.sin() * (apex - base_z), base_r)
                .normalize();
            let p = Vector3::new(r * t.cos(), r * t.sin(), z) + normal * sigma * rng.gauss();
            pts.push(Point3::from(p));
        }
    }
    PointCloud::new(pts, None).unwrap()
}

/// A thin horn pulls the control points at its tip out into a spike; without
/// the net's fairness and untangling the limit surface pleats through itself
/// there, with the defaults it does not.
#[test]
fn a_thin_horn_does_not_tangle_the_limit_surface() {
    use subdyn::fit::init::{InitParams, initial_mesh};
    let cloud = horned_sphere_scan(12_000, 0.002, 7);
    let (init, _) = initial_mesh(&cloud, &InitParams::default()).unwrap();
    let fit =
        |params: &FitParams| fit_point_cloud(&cloud, &init, params, &mut |_, _, _| {}).unwrap();
    let plain = FitParams {
        fairness: 0.0,
        untangle_rounds: 0,
        final_untangle_rounds: 0,
        ..Default::default()
    };
    let tangled = fit(&plain).report.quality.self_intersecting_pairs;
    // The untangling after the last level alone (no refit): it starts from
    // the same fit, says so, and leaves fewer crossings, moving few control
    // points a little.
    let after = fit(&FitParams {
        final_untangle_rounds: 4,
        ..plain.clone()
    });
    let u = &after.report.final_untangling;
    let left = after.report.quality.self_intersecting_pairs;
    let fit_default = fit(&FitParams::default());
    let (pairs, warnings) = (
        fit_default.report.quality.self_intersecting_pairs,
        &fit_default.report.quality.warnings,
    );
    eprintln!(
        "self-intersecting pairs: {tangled} without fairness or untangling, {left} after the final \
         untangling alone ({u:?}), {pairs} with the defaults"
    );
    assert!(
        tangled > 0,
        "the horn no longer tangles a plain fit: the test tests nothing"
    );
    assert_eq!(u.pairs_before, tangled);
    assert!(u.rounds > 0 && left < tangled, "{u:?}: {left} pairs left");
    let n = after.control.num_vertices();
    assert!(
        u.moved_control_points > 0 && u.moved_control_points < n / 10,
        "{u:?} of {n}"
    );
    assert!(u.largest_move < 0.02 * after.report.diameter, "{u:?}");
    assert_eq!(pairs, 0, "{warnings:?}");
}

/// The untangling's re-check, which evaluates again only the faces whose
/// limit surface moved and tests again only the triangles that moved, gives
/// what a check from scratch gives (points, normals, pairs), on a cube
/// refined once with a corner pushed through the opposite side and then
/// some points moved back; triangles and quads mixed in the cage.
#[test]
fn the_untangling_re_check_equals_a_check_from_scratch() {
    use subdyn::fit::quality::SelfIntersections;
    let cube = subdyn::examples::cube();
    let h = Refiner::new(&cube, &RefineOptions::default())
        .unwrap()
        .refine_uniform(1)
        .unwrap();
    let mut mesh = h.mesh(1, h.stencil(0).apply(&cube.positions).unwrap());
    // One quad split into two triangles, so the tiles are sub-faces.
    let f0 = mesh.face(0).to_vec();
    let mut faces: Vec<Vec<u32>> = (1..mesh.num_faces())
        .map(|f| mesh.face(f).to_vec())
        .collect();
    faces.push(vec![f0[0], f0[1], f0[2]]);
    faces.push(vec![f0[0], f0[2], f0[3]]);
    mesh = PolyMesh::from_faces(mesh.positions.clone(), &faces).unwrap();
    let refiner = Refiner::new(&mesh, &RefineOptions::default()).unwrap();
    let start = SelfIntersections::of(&refiner, &mesh.positions, 4).unwrap();
    assert!(start.pairs.is_empty(), "the cube does not cross itself");
    let centre = Point3::from(
        mesh.positions.iter().map(|p| p.coords).sum::<Vector3>() / mesh.num_vertices() as Real,
    );
    let mut pushed = mesh.positions.clone();
    let corner = (0..pushed.len())
        .max_by(|&a, &b| {
            (pushed[a] - centre)
                .norm()
                .total_cmp(&(pushed[b] - centre).norm())
        })
        .unwrap();
    pushed[corner] = centre + 3.0 * (centre - pushed[corner]);
    let mut back = pushed.clone();
    back[corner] = mesh.positions[corner] + Vector3::new(0.01, 0.0, 0.0);
    let moved = start.moved(&refiner, &pushed).unwrap();
    let again = moved.moved(&refiner, &back).unwrap();
    for (got, p) in [(&moved, &pushed), (&again, &back)] {
        let fresh = SelfIntersections::of(&refiner, p, 4).unwrap();
        assert_eq!(got.positions, fresh.positions);
        assert_eq!(got.normals, fresh.normals);
        assert_eq!(got.pairs, fresh.pairs);
    }
    assert!(
        !moved.pairs.is_empty(),
        "the pushed corner must cross the cube"
    );
}

/// Half sides of the machined block of [`block_scan`].
const BLOCK: [Real; 3] = [0.8, 0.5, 0.3];

/// A fixed rotation (about an oblique axis), so that no edge of the block
/// runs along a coordinate axis (or a voxel row of the initial model).
fn block_rotation() -> nalgebra::Rotation3<Real> {
    nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)),
        0.7,
    )
}

/// Distance of `p` (in the block's rotated frame) to the block's surface.
fn block_distance(p: &Point3) -> Real {
    let q = block_rotation().inverse() * p.coords;
    let d = Vector3::from_fn(|i, _| q[i].abs() - BLOCK[i]);
    let outside = d.map(|x| x.max(0.0)).norm();
    outside + d.max().min(0.0).abs()
}

/// `n` points, area-uniform, on the surface of a rotated block (12 sharp
/// edges at 90 degrees), with Gaussian noise of `sigma` along the normal.
fn block_scan(n: usize, sigma: Real, seed: u64) -> PointCloud {
    let mut rng = Rng(seed);
    let [a, b, c] = BLOCK;
    let areas = [b * c, a * c, a * b];
    let total: Real = areas.iter().sum();
    let pts = (0..n)
        .map(|_| {
            let mut pick = rng.uniform() * total;
            let axis = (0..3)
                .find(|&i| {
                    pick -= areas[i];
                    pick < 0.0
                })
                .unwrap_or(2);
            let side = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            let mut q = Vector3::from_fn(|i, _| BLOCK[i] * (2.0 * rng.uniform() - 1.0));
            q[axis] = side * (BLOCK[axis] + sigma * rng.gauss());
            Point3::from(block_rotation() * q)
        })
        .collect();
    PointCloud::new(pts, None).unwrap()
}

/// Mean and largest distance of the fitted limit surface (with its creases)
/// to the block.
fn block_deviation(fit: &subdyn::fit::FitResult) -> (Real, Real) {
    let r = Refiner::new(&fit.control, &subdyn::fit::crease_options(&fit.creases)).unwrap();
    let (tess, _) = tessellate(&r, &fit.control.positions, 4).unwrap();
    let d: Vec<Real> = tess.positions.iter().map(block_distance).collect();
    (
        d.iter().sum::<Real>() / d.len() as Real,
        d.iter().cloned().fold(0.0, f64::max),
    )
}

/// The edges of a machined block are found in its scan and tagged on the
/// control mesh: every tagged edge lies along an edge of the block, the
/// surface is closer to the block than the same fit without creases, the
/// tags survive writing (OBJ `t crease` lines, a tag file beside a PLY),
/// and a smooth sphere gets none.
#[test]
fn the_sharp_edges_of_a_block_are_tagged_as_creases() {
    use subdyn::fit::init::InitParams;
    use subdyn::fit::{FitStart, fit_from_start};
    let cloud = block_scan(12_000, 0.001, 3);
    let fit = |crease_angle: Real, tolerance_pct: Real| {
        let params = FitParams {
            crease_angle,
            tolerance_pct,
            ..Default::default()
        };
        let start = FitStart::Method(InitParams::default());
        fit_from_start(&cloud, &start, &params, &mut |_, _, _| {})
            .unwrap()
            .result
    };
    let (sharp, smooth) = (fit(50.0, 0.1), fit(0.0, 0.1));
    // With a tighter tolerance the tags go through refined levels.
    let finer = fit(50.0, 0.03);
    assert!(smooth.creases.is_empty());
    assert!(
        sharp.creases.len() >= 12,
        "{} crease edges",
        sharp.creases.len()
    );
    assert!(finer.report.levels.len() > sharp.report.levels.len());
    assert!(
        finer.creases.len() > sharp.creases.len(),
        "{} crease edges after refinement, {} before",
        finer.creases.len(),
        sharp.creases.len()
    );
    // Each end of a tagged edge is near an edge of the block: off the
    // surface by less than a tenth of the smallest side along two axes.
    for fit in [&sharp, &finer] {
        for &(i, j, s) in &fit.creases {
            assert_eq!(s, subdyn::topology::SHARPNESS_INFINITE);
            for v in [i, j] {
                let q = block_rotation().inverse() * fit.control.positions[v as usize].coords;
                let near_faces = (0..3)
                    .filter(|&k| (q[k].abs() - BLOCK[k]).abs() < 0.06)
                    .count();
                assert!(near_faces >= 2, "crease vertex {v} at {q:?} is on no edge");
            }
        }
    }
    // Fewer control points, and closer.
    assert!(sharp.control.num_vertices() < smooth.control.num_vertices());
    let (mean_sharp, max_sharp) = block_deviation(&sharp);
    let (mean_smooth, max_smooth) = block_deviation(&smooth);
    // (Below the noise, finer levels fit the noise: compare with the smooth
    // fit, not with level 0.)
    let (mean_finer, _) = block_deviation(&finer);
    assert!(mean_finer < mean_smooth);
    println!(
        "block: {} crease edges, {} control points; mean {mean_sharp:.5} max {max_sharp:.5} with them, {} control points, {mean_smooth:.5} {max_smooth:.5} without",
        sharp.creases.len(),
        sharp.control.num_vertices(),
        smooth.control.num_vertices()
    );
    assert!(mean_sharp < 0.9 * mean_smooth);
    assert!(max_sharp < max_smooth);

    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("block.obj");
    assert_eq!(
        subdyn::io::write_control_mesh(&obj, &sharp.control, &sharp.creases).unwrap(),
        None
    );
    assert_eq!(
        subdyn::io::read_obj_tags(&obj).unwrap().tags.creases,
        sharp.creases
    );
    assert_eq!(subdyn::io::read_mesh(&obj).unwrap(), sharp.control);
    let ply = dir.path().join("block.ply");
    let beside = subdyn::io::write_control_mesh(&ply, &sharp.control, &sharp.creases)
        .unwrap()
        .expect("a PLY control mesh gets its creases beside it");
    assert_eq!(beside, dir.path().join("block.ply.creases"));
    assert_eq!(
        subdyn::io::read_tags(&beside).unwrap().creases,
        sharp.creases
    );

    let sphere = sphere_scan(6000, 0.001, 4);
    let start = FitStart::Method(InitParams::default());
    let round = fit_from_start(&sphere, &start, &FitParams::default(), &mut |_, _, _| {})
        .unwrap()
        .result;
    assert!(
        round.creases.is_empty(),
        "{} creases on a sphere",
        round.creases.len()
    );
}

/// An open scan's boundary is not a crease: the refiner marks boundary
/// edges infinitely sharp, and carrying creases through the levels must
/// not take them for creases found in the data (a smooth open patch fitted
/// over several levels has none).
#[test]
fn an_open_scan_has_no_creases_on_its_boundary() {
    use subdyn::fit::init::{InitKind, InitParams};
    use subdyn::fit::{FitStart, fit_from_start};
    let mut rng = Rng(11);
    let pts: Vec<Point3> = (0..8000)
        .map(|_| {
            let (x, y) = (2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
            Point3::new(x, y, 0.3 * (x * x - y * y) + 0.001 * rng.gauss())
        })
        .collect();
    let cloud = PointCloud::new(pts, None).unwrap();
    let start = FitStart::Method(InitParams {
        kind: InitKind::Open,
        ..Default::default()
    });
    let params = FitParams {
        tolerance_pct: 0.01,
        ..Default::default()
    };
    let fit = fit_from_start(&cloud, &start, &params, &mut |_, _, _| {})
        .unwrap()
        .result;
    assert!(fit.report.levels.len() > 1, "the fit refines");
    assert!(fit.creases.is_empty(), "{} creases", fit.creases.len());
}

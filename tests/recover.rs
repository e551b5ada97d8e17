//! Recovering shapes from volumes: analytic volumes with known surfaces,
//! the `recover` verb end to end, and its bad inputs.

mod common;

use common::sdf::{recover_quietly, sdf_volume, surface_error, write_raw};

use subdyn::fit::Refinement;
use subdyn::fit::recover::{
    RecoverParams, RecoverStart, component_cage, initial_model, prepare_volume,
    prepare_volume_owned, recover_shape, seed_cage,
};
use subdyn::forces::BoundaryModel;
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real};
use subdyn::subdivision::{RefineOptions, Refiner};

#[test]
fn a_seed_grows_to_a_sphere_iso_surface() {
    let c = Point3::new(24.0, 24.0, 24.0);
    let r = 15.0;
    let sdf = move |p: Point3| (p - c).norm() - r;
    let vol = sdf_volume([48, 48, 48], [1.0; 3], sdf);
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        ..Default::default()
    };
    let prepared = prepare_volume(&vol, &params).unwrap();
    let init = seed_cage(c + subdyn::math::Vector3::new(2.0, -1.0, 1.0), 3.0).unwrap();
    let out = recover_quietly(&prepared, &init, &[], &params);
    for l in &out.report.levels {
        println!(
            "level {} cps {} samples {} steps {} p95 {:.3} vox unresolved {:.3} {:.2}s",
            l.level, l.control_points, l.samples, l.steps, l.offsets.p95, l.unresolved, l.seconds
        );
    }
    let (max, mean) = surface_error(&out.control, sdf);
    println!(
        "sphere: max {max:.3} mean {mean:.3} voxels; {}",
        out.report.stop_reason
    );
    assert!(out.report.converged, "{}", out.report.stop_reason);
    assert!(mean < 0.25 && max < 1.0, "mean {mean} max {max}");
}

#[test]
fn a_torus_is_recovered_from_its_thresholded_component_with_edges() {
    let c = Point3::new(30.0, 30.0, 20.0);
    let (big, small) = (18.0, 7.0);
    let sdf = move |p: Point3| {
        let d = p - c;
        let q = ((d.x * d.x + d.y * d.y).sqrt() - big, d.z);
        (q.0 * q.0 + q.1 * q.1).sqrt() - small
    };
    // Anisotropic voxels: 1 × 1 × 1.5.
    let vol = sdf_volume([60, 60, 27], [1.0, 1.0, 1.5], sdf);
    let params = RecoverParams::default();
    let prepared = prepare_volume(&vol, &params).unwrap();
    let cage = component_cage(
        &prepared.smoothed,
        &prepared.smoothed,
        prepared.inside_level,
        true,
        None,
        12,
    )
    .unwrap();
    assert_eq!(cage.genus, 1);
    let out = recover_quietly(&prepared, &cage.mesh, &cage.boundary, &params);
    for l in &out.report.levels {
        println!(
            "level {} cps {} samples {} steps {} p95 {:.3} vox unresolved {:.3} {:.2}s",
            l.level, l.control_points, l.samples, l.steps, l.offsets.p95, l.unresolved, l.seconds
        );
    }
    let (max, mean) = surface_error(&out.control, sdf);
    println!(
        "torus: max {max:.3} mean {mean:.3}; {}",
        out.report.stop_reason
    );
    assert!(mean < 0.3 && max < 1.5, "mean {mean} max {max}");
    assert!(subdyn::fit::recover::poor_result(&out.report, &params).is_empty());
}

/// A ball with a rod 2 voxels thick and 14 long (a leg, a vessel): the
/// automatic cage keeps the rod, which blocks of the cage's size (3 voxels
/// at resolution 12) would lose, and the recovered surface reaches its tip.
#[test]
fn a_rod_two_voxels_thick_is_kept_by_the_automatic_cage() {
    let c = Point3::new(16.0, 20.0, 20.0);
    let (from, tip) = (Point3::new(22.0, 20.0, 20.0), Point3::new(36.0, 20.0, 20.0));
    let sdf = move |p: Point3| {
        let ball = (p - c).norm() - 9.0;
        let t = ((p - from).dot(&(tip - from)) / (tip - from).norm_squared()).clamp(0.0, 1.0);
        let rod = (p - (from + t * (tip - from))).norm() - 1.0;
        ball.min(rod)
    };
    // Cubic voxels, and voxels half as deep along y (the rod is then two
    // voxels across in z, four in y).
    for (dims, spacing) in [([42, 40, 40], [1.0; 3]), ([42, 80, 40], [1.0, 0.5, 1.0])] {
        let vol = sdf_volume(dims, spacing, sdf);
        let params = RecoverParams {
            boundary: BoundaryModel::Iso { value: 0.5 },
            ..Default::default()
        };
        let prepared = prepare_volume(&vol, &params).unwrap();
        let cage =
            component_cage(&prepared.smoothed, &prepared.smoothed, 0.5, true, None, 12).unwrap();
        assert!(cage.block >= 3, "block {}", cage.block);
        let out = recover_quietly(&prepared, &cage.mesh, &cage.boundary, &params);
        let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
        let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
        let reach = tess
            .positions
            .iter()
            .map(|p| p.x)
            .fold(Real::MIN, Real::max);
        let (max, mean) = surface_error(&out.control, sdf);
        println!(
            "spacing {spacing:?}: cage {} vertices (blocks of {}, {} voxels lost, simplified from {:?}); reach x = {reach:.2} (tip 37); max {max:.3} mean {mean:.3} voxels; {}",
            cage.mesh.num_vertices(),
            cage.block,
            cage.lost_voxels,
            cage.simplified_from,
            out.report.stop_reason
        );
        assert!(reach > 35.5, "the rod ends at x = {reach}, not 37");
        assert!(mean < 0.3 && max < 1.0, "mean {mean} max {max}");
        assert!(subdyn::fit::recover::poor_result(&out.report, &params).is_empty());
    }
}

/// Two-sided forces (issue 25 item 2): started from a cage of the ball
/// alone, the rod of the previous test is missing from the model; the
/// image springs along the ball's normals never reach it, but the rod's
/// iso-surface points outside the surface pull the surface out along it.
#[test]
fn a_part_missing_from_the_cage_grows_back_by_the_two_sided_forces() {
    let c = Point3::new(16.0, 20.0, 20.0);
    let (from, tip) = (Point3::new(22.0, 20.0, 20.0), Point3::new(36.0, 20.0, 20.0));
    let sdf = move |p: Point3| {
        let ball = (p - c).norm() - 9.0;
        let t = ((p - from).dot(&(tip - from)) / (tip - from).norm_squared()).clamp(0.0, 1.0);
        let rod = (p - (from + t * (tip - from))).norm() - 2.0;
        ball.min(rod)
    };
    let vol = sdf_volume([42, 40, 40], [1.0; 3], sdf);
    let reach_with = |weight: Real| {
        let params = RecoverParams {
            boundary: BoundaryModel::Iso { value: 0.5 },
            two_sided_weight: weight,
            ..Default::default()
        };
        let prepared = prepare_volume(&vol, &params).unwrap();
        let boundary = component_cage(&prepared.smoothed, &prepared.smoothed, 0.5, true, None, 12)
            .unwrap()
            .boundary;
        // The ball's cage: the rod is not in it.
        let ball = seed_cage(c, 9.0).unwrap();
        let out = recover_quietly(&prepared, &ball, &boundary, &params);
        let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
        let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
        let reach = tess
            .positions
            .iter()
            .map(|p| p.x)
            .fold(Real::MIN, Real::max);
        let last = out.report.levels.last().unwrap();
        println!(
            "two-sided weight {weight}: reach x = {reach:.2} (tip 38, ball 25); {} control points, {:.2} % of {} iso points unmatched; {}",
            out.control.num_vertices(),
            100.0 * last.unmatched,
            last.boundary_points,
            out.report.stop_reason
        );
        (reach, last.unmatched)
    };
    let (without, _) = reach_with(0.0);
    let (with, unmatched) = reach_with(RecoverParams::default().two_sided_weight);
    assert!(
        without < 30.0,
        "the image springs alone reached x = {without}"
    );
    assert!(with > 36.0, "the rod ends at x = {with}, not 38");
    assert!(unmatched < 0.05, "{unmatched}");
}

#[test]
fn adaptive_levels_keep_within_the_control_point_budget() {
    // The ball-and-rod volume from its automatic cage, refined adaptively;
    // its iso-surface points set the budget.
    let c = Point3::new(16.0, 20.0, 20.0);
    let sdf = move |p: Point3| {
        let t = ((p.x - 22.0) / 14.0).clamp(0.0, 1.0);
        let rod = (p - Point3::new(22.0 + 14.0 * t, 20.0, 20.0)).norm() - 2.0;
        ((p - c).norm() - 9.0).min(rod)
    };
    let vol = sdf_volume([42, 40, 40], [1.0; 3], sdf);
    let run = |share: Real| {
        // A tolerance that level 0 cannot meet, so that levels are added.
        let params = RecoverParams {
            boundary: BoundaryModel::Iso { value: 0.5 },
            max_control_share: share,
            tolerance_voxels: 0.05,
            min_edge_voxels: 0.5,
            ..Default::default()
        };
        let prepared = prepare_volume(&vol, &params).unwrap();
        let cage =
            component_cage(&prepared.smoothed, &prepared.smoothed, 0.5, true, None, 6).unwrap();
        let boundary = cage.boundary;
        let out = recover_quietly(&prepared, &cage.mesh, &boundary, &params);
        println!(
            "share {share}: {} control points of {} iso points; {}",
            out.control.num_vertices(),
            boundary.len(),
            out.report.stop_reason
        );
        (out, boundary.len())
    };
    let (free, n) = run(1.0);
    let seed_points = free.report.levels[0].control_points;
    assert!(
        free.control.num_vertices() > 2 * seed_points,
        "no refinement to limit"
    );
    // A budget between the seed cage and the unlimited result binds.
    let share = (seed_points + free.control.num_vertices()) as Real / (2 * n) as Real;
    let (held, _) = run(share);
    assert!(
        held.control.num_vertices() as Real <= share * n as Real,
        "{} control points over the budget {}",
        held.control.num_vertices(),
        share * n as Real
    );
    assert!(held.control.num_vertices() > seed_points);
}

#[test]
fn the_recover_verb_writes_the_shape_report_and_slices_and_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let c = Point3::new(16.0, 16.0, 16.0);
    let sdf = move |p: Point3| (p - c).norm() - 9.0;
    let path = write_raw(dir.path(), "ball", &sdf_volume([32, 32, 32], [1.0; 3], sdf));
    let out = common::run_subdyn(
        dir.path(),
        &[
            "recover",
            path.to_str().unwrap(),
            "--seed",
            "15,16,17",
            "--iso",
            "0.5",
            "-o",
            "ball.obj",
            "--limit-out",
            "ball.ply",
            "--report",
            "r.json",
            "--slices-png",
            "slices",
            "--quiet",
        ],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("tolerance met"), "{text}");
    let fit = subdyn::io::read_mesh(dir.path().join("ball.obj")).unwrap();
    let (max, _) = surface_error(&fit, sdf);
    assert!(max < 0.5, "largest distance {max} voxels");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(report["init"]["method"], "seed");
    assert!(
        report["recover"]["levels"][0]["offsets"]["p95"]
            .as_f64()
            .unwrap()
            < 0.5
    );
    assert_eq!(
        std::fs::read_dir(dir.path().join("slices"))
            .unwrap()
            .count(),
        5
    );

    // Bad inputs: one line, exit 1, no output file.
    let flat = write_raw(
        dir.path(),
        "flat",
        &sdf_volume([8, 8, 8], [1.0; 3], |_| 5.0),
    );
    let flat = flat.to_str().unwrap();
    let path = path.to_str().unwrap();
    for (args, expect) in [
        (
            vec!["recover", path, "--seed", "100,0,0", "--iso", "0.5"],
            "outside the volume",
        ),
        (
            vec!["recover", path, "--seed", "1,1,1", "--iso", "0.5"],
            "not inside the object",
        ),
        (
            vec!["recover", path, "--iso", "7"],
            "outside the volume's range",
        ),
        (vec!["recover", flat], "constant"),
        (vec!["recover", path, "--tol=-1"], "tolerance"),
        (vec!["recover", "missing.nii"], "missing.nii"),
    ] {
        let mut args = args.clone();
        args.extend(["-o", "bad.obj", "--quiet"]);
        let out = common::run_subdyn(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(expect) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
        assert!(!dir.path().join("bad.obj").exists());
    }
}

#[test]
fn user_placed_points_pull_the_surface_where_the_image_says_otherwise() {
    // The image shows a ball of radius 9; ten points placed on radius 11
    // around its upper half pull that half out, more with a larger weight.
    let c = Point3::new(16.0, 16.0, 16.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p: Point3| {
        (p - c).norm() - 9.0
    });
    let points: Vec<Point3> = (0..10)
        .map(|i| {
            let a = i as Real * std::f64::consts::TAU / 10.0;
            c + 11.0 * subdyn::math::Vector3::new(0.6 * a.cos(), 0.6 * a.sin(), 0.8)
        })
        .collect();
    let top_radius = |weight: Real, with_points: bool| {
        let params = RecoverParams {
            boundary: BoundaryModel::Iso { value: 0.5 },
            points_weight: weight,
            // Level 0 is enough here; finer levels are the next test's.
            max_level: 0,
            ..Default::default()
        };
        let prepared = prepare_volume(&vol, &params).unwrap();
        let init = seed_cage(c, 4.0).unwrap();
        let pts = if with_points { &points[..] } else { &[] };
        let out = recover_shape(&prepared, &init, pts, &[], &params, &mut |_, _, _| {});
        let out = out.unwrap_or_else(|e| panic!("weight {weight} points {with_points}: {e}"));

        let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
        let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
        // Largest distance from the centre among surface points near the
        // direction of the placed points.
        tess.positions
            .iter()
            .filter(|p| (*p - c).normalize().z > 0.75)
            .map(|p| (p - c).norm())
            .fold(0.0, Real::max)
    };
    let none = top_radius(1.0, false);
    let weak = top_radius(0.2, true);
    let strong = top_radius(5.0, true);
    println!("top radius: image only {none:.3}, weight 0.2 {weak:.3}, weight 5 {strong:.3}");
    assert!((none - 9.0).abs() < 0.3, "{none}");
    assert!(
        weak > none + 0.1 && strong > weak + 0.1,
        "{none} {weak} {strong}"
    );
    assert!(strong < 11.2, "{strong}");
    let bad = [Point3::new(f64::NAN, 0.0, 0.0)];
    let params = RecoverParams::default();
    let prepared = prepare_volume(&vol, &params).unwrap();
    let init = seed_cage(c, 4.0).unwrap();
    assert!(recover_shape(&prepared, &init, &bad, &[], &params, &mut |_, _, _| {}).is_err());
}

/// One user point over a ball, recovered to level 2 by uniform refinement:
/// the pull is spread over a level-0 control edge, so the surface around
/// the point moves with it (a patch, not a spike), and the point is still
/// approached. (Adaptive refinement splits the faces under the point only,
/// and there the bump is narrower: 1.58 at the point, 0.32 around it.)
#[test]
fn a_user_point_pulls_a_patch_not_a_spike_at_finer_levels() {
    let c = Point3::new(16.0, 16.0, 16.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p: Point3| {
        (p - c).norm() - 9.0
    });
    let up = subdyn::math::Vector3::new(0.0, 0.0, 1.0);
    let point = c + 11.0 * up;
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        points_weight: 2.0,
        max_level: 2,
        refinement: Refinement::Uniform,
        tolerance_voxels: 1e-3,
        min_level_gain: 0.0,
        min_edge_voxels: 0.25,
        ..Default::default()
    };
    let prepared = prepare_volume(&vol, &params).unwrap();
    let init = seed_cage(c, 4.0).unwrap();
    let out = recover_shape(&prepared, &init, &[point], &[], &params, &mut |_, _, _| {}).unwrap();
    let reached = out.report.levels.len() - 1;
    let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
    let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
    // Radius beyond the ball's 9 along directions at angle θ from `up`.
    let lift = |lo: Real, hi: Real| {
        let r: Vec<Real> = tess
            .positions
            .iter()
            .filter(|p| {
                let a = (*p - c)
                    .normalize()
                    .dot(&up)
                    .clamp(-1.0, 1.0)
                    .acos()
                    .to_degrees();
                a >= lo && a < hi
            })
            .map(|p| (p - c).norm() - 9.0)
            .collect();
        r.iter().sum::<Real>() / r.len().max(1) as Real
    };
    let (top, ring) = (lift(0.0, 4.0), lift(12.0, 18.0));
    println!("level {reached}: lift at the point {top:.3}, 12–18° away {ring:.3}");
    assert_eq!(
        reached,
        2,
        "the recovery must reach level 2: {:?}",
        out.report.levels.len()
    );
    // Springs on the closest point alone (before the kernel) gave 0.59 at
    // the point and −0.13 around it: a narrow spike in a dip.
    assert!(
        top > 1.0 && top < 2.1,
        "the point pulls the surface out: {top}"
    );
    assert!(
        ring > 0.25 * top,
        "a spike: {top} at the point, {ring} around it"
    );
}

/// Preparing a volume given up to the recovery (smoothed in its own
/// memory) gives the same smoothed image, potential and inside level as
/// preparing a borrowed one, and the same errors.
#[test]
fn an_owned_volume_is_prepared_like_a_borrowed_one() {
    let c = Point3::new(8.0, 7.0, 9.0);
    let vol = sdf_volume([17, 15, 19], [1.0, 1.0, 1.2], |p| (p - c).norm() - 4.5);
    for boundary in [
        BoundaryModel::Iso { value: 0.5 },
        BoundaryModel::Edge { min_strength: 0.1 },
    ] {
        let params = RecoverParams {
            boundary,
            ..Default::default()
        };
        let a = prepare_volume(&vol, &params).unwrap();
        let b = prepare_volume_owned(vol.clone(), &params).unwrap();
        assert_eq!(a.smoothed.data(), b.smoothed.data());
        assert_eq!(
            a.potential.as_ref().map(|p| p.data()),
            b.potential.as_ref().map(|p| p.data())
        );
        assert_eq!(a.inside_level, b.inside_level);
        assert_eq!(a.sigma, b.sigma);
    }
    let flat = vol.with_data(vec![0.25; vol.data().len()]).unwrap();
    assert!(prepare_volume_owned(flat, &RecoverParams::default()).is_err());
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 2.0 },
        ..Default::default()
    };
    assert!(prepare_volume_owned(vol, &params).is_err());
}

/// Parts (issue 25 item 1): a body and a smaller ball apart from it (a
/// hoof the threshold cut off, a bone fragment) each get a closed cage and
/// both are recovered, as marching cubes keeps both; a seed in the body
/// keeps the body alone; a speck under the part size is left out.
#[test]
fn every_part_of_the_object_is_recovered_unless_a_seed_picks_one() {
    let (body, part, speck) = (
        Point3::new(16.0, 20.0, 20.0),
        Point3::new(34.0, 20.0, 20.0),
        Point3::new(34.0, 32.0, 32.0),
    );
    let sdf = move |p: Point3| {
        ((p - body).norm() - 9.0)
            .min((p - part).norm() - 4.0)
            .min((p - speck).norm() - 1.0)
    };
    let vol = sdf_volume([42, 40, 40], [1.0; 3], sdf);
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        ..Default::default()
    };
    let prepared = prepare_volume(&vol, &params).unwrap();
    let cage = component_cage(&prepared.smoothed, &prepared.smoothed, 0.5, true, None, 12).unwrap();
    assert_eq!((cage.components, cage.parts), (3, 2));
    let out = recover_quietly(&prepared, &cage.mesh, &cage.boundary, &params);
    assert!(subdyn::fit::recover::poor_result(&out.report, &params).is_empty());
    let topo = subdyn::fit::init::surface_topology(&out.control).unwrap();
    assert_eq!((topo.components, topo.boundary_loops), (2, 0));
    let (max, mean) = surface_error(&out.control, sdf);
    assert!(mean < 0.3 && max < 1.0, "mean {mean} max {max}");
    // Both parts are there: the limit surface reaches into the small ball.
    let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
    let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
    assert!(
        tess.positions
            .iter()
            .any(|p| (p - part).norm() < 4.5 && p.x > 36.0)
    );
    let seeded = component_cage(
        &prepared.smoothed,
        &prepared.smoothed,
        0.5,
        true,
        Some(body),
        12,
    )
    .unwrap();
    assert_eq!(seeded.parts, 1);
    assert!(seeded.mesh.positions.iter().all(|p| p.x < 27.0));
}

/// A rod the cage's volume lacks (as when its extra smoothing cuts a thin
/// part below the level) but the forces' volume holds: its iso-surface
/// points join the cage's for the two-sided forces, and a surface started
/// from the ball grows out along it; the ball's own rim is not taken twice.
#[test]
fn a_part_only_the_forces_volume_holds_still_pulls_the_surface_out() {
    let c = Point3::new(16.0, 20.0, 20.0);
    let (from, tip) = (Point3::new(22.0, 20.0, 20.0), Point3::new(36.0, 20.0, 20.0));
    let ball = move |p: Point3| (p - c).norm() - 9.0;
    let with_rod = move |p: Point3| {
        let t = ((p - from).dot(&(tip - from)) / (tip - from).norm_squared()).clamp(0.0, 1.0);
        ball(p).min((p - (from + t * (tip - from))).norm() - 2.0)
    };
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        ..Default::default()
    };
    let cage_volume = prepare_volume(&sdf_volume([42, 40, 40], [1.0; 3], ball), &params).unwrap();
    let forces = prepare_volume(&sdf_volume([42, 40, 40], [1.0; 3], with_rod), &params).unwrap();
    let alone = component_cage(
        &cage_volume.smoothed,
        &cage_volume.smoothed,
        0.5,
        true,
        None,
        12,
    )
    .unwrap();
    let cage =
        component_cage(&cage_volume.smoothed, &forces.smoothed, 0.5, true, None, 12).unwrap();
    let reach = |points: &[Point3]| points.iter().map(|p| p.x).fold(Real::MIN, Real::max);
    assert!(reach(&cage.mesh.positions) < 27.0);
    assert!(reach(&alone.boundary) < 26.0 && reach(&cage.boundary) > 36.0);
    // Only the rod's points were added: the ball's rim a voxel from it is not.
    let added = &cage.boundary[alone.boundary.len()..];
    assert_eq!(&cage.boundary[..alone.boundary.len()], &alone.boundary[..]);
    assert!(added.iter().all(|p| p.x > 24.0), "{added:?}");
    // From the ball's coarse cage, with each set of points.
    let reach_from = |boundary: &[Point3]| {
        let start = seed_cage(c, 9.0).unwrap();
        let out = recover_quietly(&forces, &start, boundary, &params);
        let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
        let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
        let poor = subdyn::fit::recover::poor_result(&out.report, &params);
        (reach(&tess.positions), poor)
    };
    let (grown, poor) = reach_from(&cage.boundary);
    let (stayed, _) = reach_from(&alone.boundary);
    println!("surface reaches x = {grown:.2} with the rod's points, {stayed:.2} without");
    assert!(poor.is_empty(), "{poor:?}");
    assert!(grown > 36.0 && stayed < 30.0, "{grown} vs {stayed}");
}

/// A ball with a cone-shaped horn (the anvil's case): at the first level
/// the 95th percentile of the offsets meets the tolerance while a few
/// samples near the tip are off by more than 1.2 × it (0.63 voxel); the
/// level is refined there (a few faces) and the finer level's samples all
/// lie within that limit. (Without the rule the recovery stops at level 0.)
#[test]
fn a_horn_tip_the_cage_misses_refines_the_level_there() {
    let c = Point3::new(32.0, 40.0, 40.0);
    let tip = Point3::new(80.0, 40.0, 40.0);
    let sdf = move |p: Point3| {
        let ball = (p - c).norm() - 18.0;
        // A cone from radius 8 at x = 40 to a point at the tip.
        let t = ((p.x - 40.0) / (tip.x - 40.0)).clamp(0.0, 1.0);
        let r = 8.0 * (1.0 - t);
        let q = Point3::new(40.0 + t * (tip.x - 40.0), 40.0, 40.0);
        let horn = ((p - q).norm() - r).max(40.0 - p.x).max(p.x - tip.x);
        ball.min(horn)
    };
    let vol = sdf_volume([96, 80, 80], [1.0; 3], sdf);
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        ..Default::default()
    };
    let prepared = prepare_volume(&vol, &params).unwrap();
    let start = RecoverStart::Auto {
        seed: None,
        resolution: 12,
    };
    let init = initial_model(&prepared, &start, true).unwrap();
    let out = recover_quietly(&prepared, &init.mesh, &init.boundary, &params);
    let levels = &out.report.levels;
    for l in levels {
        println!(
            "level {} cps {} p95 {:.3} max {:.3} vox",
            l.level, l.control_points, l.offsets.p95, l.offsets.max
        );
    }
    println!("{}", out.report.stop_reason);
    let limit = 1.2 * params.tolerance_voxels;
    assert!(levels[0].offsets.p95 <= params.tolerance_voxels);
    assert!(levels[0].offsets.max > limit);
    assert!(levels.len() > 1, "{}", out.report.stop_reason);
    let last = &levels[out.report.returned_level];
    assert!(last.offsets.max <= limit, "max offset {}", last.offsets.max);
    assert!(last.control_points < levels[0].control_points + levels[0].control_points / 10);
}

//! A data-gen volume of an object larger than its box (a unit sphere whose
//! top the grid cuts off at z = 0.57, as CT and MRI cut a head at the neck),
//! recovered by `subdyn::fit::recover` with its defaults: no error, a closed
//! surface, and the cap on the box face (within half a voxel), as marching
//! cubes on a padded volume gives.

mod common;

use common::{json, ok, scratch};
use subdyn::fit::init::surface_topology;
use subdyn::fit::recover::{
    RecoverParams, component_cage, poor_result, prepare_volume_owned, recover_shape,
};
use subdyn::forces::BoundaryModel;
use subdyn::io::{VolumeReadOptions, read_volume};
use subdyn::limit::tessellate;
use subdyn::subdivision::{RefineOptions, Refiner};

#[test]
fn a_sphere_cut_by_the_box_is_recovered_closed_with_its_cap_on_the_box_face() {
    let dir = scratch("recover-cut");
    // 40 × 40 × 30 voxels of 0.06: x and y hold the sphere, z stops at
    // sample 0.54 (box face 0.57), so the grid cuts a disc of radius 0.82.
    ok(
        &dir,
        &[
            "volume",
            "sphere",
            "-o",
            "cut.raw",
            "--format",
            "raw",
            "--dims",
            "40,40,30",
            "--spacing",
            "0.06,0.06,0.06",
            "--origin=-1.17,-1.17,-1.2",
            "--blur",
            "0.03",
            "--noise",
            "0.05",
        ],
    );
    let side = json(&dir.join("cut.json"));
    let iso = side["iso_value"].as_f64().expect("iso");
    let (voxel, face) = (0.06, 0.54 + 0.03);
    let volume = read_volume(dir.join("cut.json"), &VolumeReadOptions::default())
        .expect("the raw volume reads")
        .volume;
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: iso },
        ..Default::default()
    };
    let prepared = prepare_volume_owned(volume, &params).expect("prepared");
    let cage = component_cage(
        &prepared.smoothed,
        &prepared.smoothed,
        prepared.inside_level,
        true,
        None,
        24,
    )
    .expect("a cage of the cut component");
    let out = recover_shape(
        &prepared,
        &cage.mesh,
        &[],
        &cage.boundary,
        &params,
        &mut |_, _, _| {},
    )
    .expect("the cut sphere is recovered without error");
    assert!(
        poor_result(&out.report, &params).is_empty(),
        "{:?}",
        poor_result(&out.report, &params)
    );
    let topo = surface_topology(&out.control).expect("topology");
    assert_eq!(
        (topo.boundary_loops, topo.genus, topo.components),
        (0, 0, 1)
    );

    let refiner = Refiner::new(&out.control, &RefineOptions::default()).expect("refiner");
    let (tess, _) = tessellate(&refiner, &out.control.positions, 4).expect("tessellation");
    let p = &tess.positions;
    // The cap: surface points over the cut disc, 3 voxels in from its rim.
    let rim = (1.0f64 - face * face).sqrt();
    let cap: Vec<f64> = p
        .iter()
        .filter(|q| q.z > 0.0 && q.x.hypot(q.y) < rim - 3.0 * voxel)
        .map(|q| (q.z - face).abs() / voxel)
        .collect();
    let worst = cap.iter().cloned().fold(0.0, f64::max);
    let top = p.iter().map(|q| q.z).fold(f64::MIN, f64::max);
    // The rest of the sphere, away from the rim: on the unit sphere.
    let sphere = p
        .iter()
        .filter(|q| q.z < face - 3.0 * voxel)
        .map(|q| ((q.coords.norm() - 1.0) / voxel).abs())
        .fold(0.0, f64::max);
    println!(
        "{} cap points, farthest {worst:.3} voxels from the box face; top {top:.4} (face {face}); sphere max {sphere:.3} voxels; {}",
        cap.len(),
        out.report.stop_reason
    );
    assert!(cap.len() > 500, "the cap is covered: {}", cap.len());
    assert!(
        worst <= 0.5,
        "the cap lies {worst} voxels from the box face"
    );
    assert!(
        top <= face + 0.5 * voxel,
        "the surface passes the box face: {top}"
    );
    assert!(sphere < 1.0, "the sphere is {sphere} voxels off");
}

//! No silent garbage (issue 25): a thin plate at 64 × 48 × 24 voxels (its
//! sheet a few voxels thick, a slot through it) whose automatic cage pleats
//! instead of settling on the boundary. The recovery must report the result
//! as poor (the CLI then exits 1 and writes nothing unless --accept-poor),
//! naming the offsets; it used to return it as a good one.

mod common;

use common::{json, ok, scratch};
use subdyn::fit::recover::{
    RecoverParams, RecoverStart, initial_model, poor_result, prepare_volume_owned, recover_shape,
};
use subdyn::forces::BoundaryModel;
use subdyn::io::{VolumeReadOptions, read_volume};

#[test]
fn a_surface_that_does_not_settle_on_the_boundary_is_a_poor_result() {
    let dir = scratch("recover-poor");
    ok(
        &dir,
        &[
            "volume",
            "plate",
            "-o",
            "plate.raw",
            "--format",
            "raw",
            "--dims",
            "64,48,24",
            "--blur",
            "0.03",
            "--noise",
            "0.05",
            "--seed",
            "5",
        ],
    );
    let iso = json(&dir.join("plate.json"))["iso_value"]
        .as_f64()
        .expect("iso");
    let volume = read_volume(dir.join("plate.json"), &VolumeReadOptions::default())
        .expect("the raw volume reads")
        .volume;
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: iso },
        ..Default::default()
    };
    let prepared = prepare_volume_owned(volume, &params).expect("prepared");
    let start = RecoverStart::Auto {
        seed: None,
        resolution: 24,
    };
    let init = initial_model(&prepared, &start, true).expect("a cage");
    let out = recover_shape(
        &prepared,
        &init.mesh,
        &[],
        &init.boundary,
        &params,
        &mut |_, _, _| {},
    )
    .expect("recovered");
    let last = &out.report.levels[out.report.returned_level];
    let why = poor_result(&out.report, &params);
    println!(
        "p95 {:.2} voxels after {} steps: {why:?}",
        last.offsets.p95, last.steps
    );
    assert!(
        last.offsets.p95 > 1.0,
        "the plate settled: p95 {}",
        last.offsets.p95
    );
    assert!(
        why.iter().any(|w| w.contains("off the boundary")),
        "{why:?}"
    );
}

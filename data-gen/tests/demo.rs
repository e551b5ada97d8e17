//! `data-gen demo` regenerates the committed demo data set byte for byte,
//! and the committed files load through subdyn.

mod common;

use std::path::Path;

use common::{ok, scratch};

/// The workspace root (the demo runs from there).
fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

const FILES: [&str; 3] = [
    "spot_scan.ply.gz",
    "spot_scan.json",
    "spot_scan.truth.obj.gz",
];

#[test]
fn committed_demo_files_load_and_are_small() {
    let demo = root().join("data/demo");
    let cloud = subdyn::io::read_points(demo.join(FILES[0])).expect("demo scan loads");
    let truth = subdyn::io::read_mesh(demo.join(FILES[2])).expect("demo truth loads");
    let side = common::json(&demo.join(FILES[1]));
    assert_eq!(side["counts"]["total"], cloud.len());
    assert!(
        (10_000..=30_000).contains(&cloud.len()),
        "{} points",
        cloud.len()
    );
    assert_eq!(truth.num_vertices(), 2930);
    let total: u64 = FILES
        .iter()
        .map(|f| std::fs::metadata(demo.join(f)).unwrap().len())
        .sum();
    assert!(total < 1_000_000, "demo data set is {total} bytes");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn demo_regenerates_the_committed_files() {
    let out = scratch("demo");
    let out_arg = out.to_string_lossy().into_owned();
    ok(root(), &["demo", "-o", &out_arg]);
    for f in FILES {
        let fresh = std::fs::read(out.join(f)).unwrap();
        let committed = std::fs::read(root().join("data/demo").join(f)).unwrap();
        assert!(
            fresh == committed,
            "{f} differs from data/demo/{f}: rerun `cargo run --release -p data-gen -- demo`"
        );
    }
}

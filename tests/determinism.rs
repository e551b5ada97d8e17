//! The same input gives the same bytes whatever the thread count (issue 28,
//! item 8): `fit`, `subdivide --limit` and `recover` run with 1, 2 and 3
//! rayon threads.
//! Parallel sums are split into parts by the problem's size only
//! ([`subdyn::math::reduction_parts`]) and added in order.

mod common;

use std::path::Path;

use common::sdf::{noisy_ball_with_rod, sdf_volume, write_raw};

/// A noisy torus scan (radii 1 and 0.4) as XYZ: 6,000 points, with
/// deterministic pseudo-random offsets along the normal.
fn torus_xyz() -> String {
    let mut s = String::new();
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    for i in 0..6000 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        let noise = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.004;
        let u = std::f64::consts::TAU * (i as f64 * 0.618_033_988_75).fract();
        let v = std::f64::consts::TAU * (i as f64 * 0.754_877_666_25).fract();
        let r = 0.4 + noise;
        let (x, y, z) = (
            (1.0 + r * v.cos()) * u.cos(),
            (1.0 + r * v.cos()) * u.sin(),
            r * v.sin(),
        );
        s.push_str(&format!("{x} {y} {z}\n"));
    }
    s
}

fn run_with_threads(dir: &Path, threads: usize, args: &[&str]) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("the subdyn binary runs");
    assert!(
        out.status.success(),
        "{args:?} with {threads} threads: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn fit_and_subdivide_give_the_same_bytes_on_1_2_and_3_threads() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("torus.xyz"), torus_xyz()).unwrap();
    let mut outputs: Vec<Vec<Vec<u8>>> = Vec::new();
    for threads in [1, 2, 3] {
        let (fit, surf, sub) = (
            format!("fit{threads}.obj"),
            format!("surf{threads}.ply"),
            format!("sub{threads}.ply"),
        );
        let fit_args = [
            "fit",
            "torus.xyz",
            "-o",
            &fit,
            "--limit-out",
            &surf,
            "--quiet",
        ];
        run_with_threads(dir.path(), threads, &fit_args);
        let sub_args = [
            "subdivide",
            &fit,
            "-o",
            &sub,
            "--levels",
            "2",
            "--limit",
            "--quiet",
        ];
        run_with_threads(dir.path(), threads, &sub_args);
        outputs.push(
            [fit, surf, sub]
                .iter()
                .map(|f| std::fs::read(dir.path().join(f)).unwrap())
                .collect(),
        );
    }
    for (t, o) in outputs.iter().enumerate().skip(1) {
        for (k, name) in ["fit", "limit surface", "subdivided limit"]
            .iter()
            .enumerate()
        {
            assert!(
                o[k] == outputs[0][k],
                "the {name} differs between 1 and {} threads",
                t + 1
            );
        }
    }
    // The fit did real work: more than the initial cage.
    let obj = String::from_utf8_lossy(&outputs[0][0]).into_owned();
    assert!(obj.lines().filter(|l| l.starts_with("v ")).count() > 100);
}

/// `recover` of a ball with a rod 2 voxels thick, cut by the box (so the
/// simplified cage, the padding and `--open-at-box` all run), with noise:
/// the same control mesh and limit surface on 1, 2 and 3 threads.
#[test]
fn recover_gives_the_same_bytes_on_1_2_and_3_threads() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_raw(
        dir.path(),
        "v",
        &sdf_volume([42, 40, 32], [1.0; 3], noisy_ball_with_rod),
    );
    let mut outputs = Vec::new();
    for threads in [1, 2, 3] {
        let (obj, ply, report) = (
            format!("r{threads}.obj"),
            format!("r{threads}.ply"),
            format!("r{threads}.json"),
        );
        let args = [
            "recover",
            path.to_str().unwrap(),
            "--iso",
            "0.5",
            "--open-at-box",
            "-o",
            &obj,
            "--limit-out",
            &ply,
            "--report",
            &report,
            "--quiet",
        ];
        run_with_threads(dir.path(), threads, &args);
        outputs.push([obj, ply].map(|f| std::fs::read(dir.path().join(f)).unwrap()));
    }
    // Check the claim above: the cage was simplified (the rod was lost by
    // the blocks) and the cut was opened (the control mesh has a boundary).
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("r1.json")).unwrap()).unwrap();
    assert!(
        report["init"]["simplified_from_block"].is_u64(),
        "{}",
        report["init"]
    );
    let control = subdyn::io::read_mesh(dir.path().join("r1.obj")).unwrap();
    let topo = subdyn::fit::init::surface_topology(&control).unwrap();
    assert_eq!(topo.boundary_loops, 1);
    for (t, o) in outputs.iter().enumerate().skip(1) {
        assert!(
            o == &outputs[0],
            "recover differs between 1 and {} threads",
            t + 1
        );
    }
}

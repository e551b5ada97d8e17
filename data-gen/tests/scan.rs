//! `data-gen scan`: determinism, files that load back, points on the ground
//! truth within the noise, dropout and outlier fractions, view ids.

mod common;

use common::{json, ok, ply_views, scratch};
use subdyn::io::{read_mesh, read_points};
use subdyn::math::bbox_diagonal;
use subdyn::metrics::TriangleBvh;

const NOISY: &[&str] = &[
    "scan",
    "torus",
    "-o",
    "scan.ply",
    "--views",
    "6",
    "--resolution",
    "80,60",
    "--noise",
    "0.002",
    "--dropout",
    "0.2",
    "--outliers",
    "0.05",
];

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let (a, b, c) = (scratch("seed-a"), scratch("seed-b"), scratch("seed-c"));
    let with_seed = |s: &'static str| [NOISY, &["--seed", s]].concat();
    ok(&a, &with_seed("11"));
    ok(&b, &with_seed("11"));
    ok(&c, &with_seed("12"));
    for f in ["scan.ply", "scan.json", "scan.truth.obj"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    assert_ne!(
        std::fs::read(a.join("scan.ply")).unwrap(),
        std::fs::read(c.join("scan.ply")).unwrap()
    );
    // The ground truth does not depend on the seed.
    assert_eq!(
        std::fs::read(a.join("scan.truth.obj")).unwrap(),
        std::fs::read(c.join("scan.truth.obj")).unwrap()
    );
}

#[test]
fn noise_free_points_lie_on_the_ground_truth() {
    for (shape, extra) in [
        ("genus2", &["--perspective"][..]),
        ("anvil", &["--orthographic"][..]),
        ("bulb", &["--smooth-normals"][..]),
    ] {
        let dir = scratch("exact");
        let args = [
            &[
                "scan",
                shape,
                "-o",
                "s.ply",
                "--views",
                "5",
                "--resolution",
                "64,48",
            ][..],
            extra,
        ]
        .concat();
        ok(&dir, &args);
        let cloud = read_points(dir.join("s.ply")).expect("the scan loads through subdyn");
        let truth = read_mesh(dir.join("s.truth.obj")).expect("the ground truth loads");
        let side = json(&dir.join("s.json"));
        assert_eq!(side["counts"]["total"], cloud.len());
        assert_eq!(side["ground_truth_mesh"], "s.truth.obj");
        assert!(cloud.len() > 1000, "{shape}: {} points", cloud.len());
        let diag = bbox_diagonal(&truth.positions);
        let bvh = TriangleBvh::from_mesh(&truth).unwrap();
        let normals = cloud.normals.as_ref().expect("normals by default");
        for (p, n) in cloud.positions.iter().zip(normals) {
            let near = bvh.closest_point(*p).unwrap();
            assert!(
                near.distance <= 1e-9 * diag,
                "{shape}: {p} is {} off",
                near.distance
            );
            assert!((n.norm() - 1.0).abs() < 1e-12);
        }
        // Normals face the sensor: towards the eye of the point's view.
        let views = ply_views(&dir.join("s.ply"));
        for ((p, n), &v) in cloud.positions.iter().zip(normals).zip(&views) {
            let eye = &side["views"][v as usize]["eye"];
            let e = subdyn::math::Point3::new(
                eye[0].as_f64().unwrap(),
                eye[1].as_f64().unwrap(),
                eye[2].as_f64().unwrap(),
            );
            if side["parameters"]["projection"] == "perspective" {
                assert!(n.dot(&(e - p)) > 0.0);
            } else {
                let f = &side["views"][v as usize]["forward"];
                let f = subdyn::math::Vector3::new(
                    f[0].as_f64().unwrap(),
                    f[1].as_f64().unwrap(),
                    f[2].as_f64().unwrap(),
                );
                assert!(n.dot(&f) < 0.0);
            }
        }
    }
}

#[test]
fn noise_dropout_and_outliers_are_as_asked() {
    let dir = scratch("noise");
    ok(&dir, &[NOISY, &["--seed", "3"]].concat());
    let side = json(&dir.join("scan.json"));
    let cloud = read_points(dir.join("scan.ply")).unwrap();
    let truth = read_mesh(dir.join("scan.truth.obj")).unwrap();
    let views = ply_views(&dir.join("scan.ply"));
    let counts = &side["counts"];
    let n = |k: &str| counts[k].as_u64().unwrap() as usize;
    assert_eq!(cloud.len(), n("total"));
    assert_eq!(views.len(), n("total"));

    // View ids: in range, and as many per view as the sidecar says.
    let nv = side["views"].as_array().unwrap().len();
    assert_eq!(nv, 6);
    for (v, view) in side["views"].as_array().unwrap().iter().enumerate() {
        let here = views.iter().filter(|&&x| x == v as i32).count();
        assert_eq!(
            here as u64,
            view["points"].as_u64().unwrap() + view["outliers"].as_u64().unwrap()
        );
    }

    // Dropout: binomial, within 4 standard deviations.
    let (hits, dropped) = (n("hits") as f64, n("dropped") as f64);
    let sd = (hits * 0.2 * 0.8).sqrt();
    assert!(
        (dropped - 0.2 * hits).abs() < 4.0 * sd,
        "{dropped} of {hits} dropped"
    );
    assert_eq!(n("surface_points"), n("hits") - n("dropped"));

    // Outliers: 5 % of the output, after the surface points.
    let share = n("outliers") as f64 / n("total") as f64;
    assert!((share - 0.05).abs() < 0.002, "outlier share {share}");
    assert_eq!(
        side["outliers"]["first_index"].as_u64().unwrap() as usize,
        n("surface_points")
    );

    // Noise: surface points within a few σ of the truth and visibly off it.
    let sigma = side["parameters"]["noise_sigma"].as_f64().unwrap();
    let diag = bbox_diagonal(&truth.positions);
    assert!((sigma - 0.002 * diag).abs() < 1e-12 * diag);
    let bvh = TriangleBvh::from_mesh(&truth).unwrap();
    let surface = &cloud.positions[..n("surface_points")];
    let d: Vec<f64> = surface
        .iter()
        .map(|p| bvh.closest_point(*p).unwrap().distance)
        .collect();
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    assert!(d.iter().all(|&x| x < 6.0 * sigma));
    assert!(
        rms > 0.4 * sigma && rms < 1.05 * sigma,
        "rms {rms} vs sigma {sigma}"
    );

    // Outliers lie in the enlarged box, mostly off the surface.
    let bx = &side["outliers"]["box"];
    for p in &cloud.positions[n("surface_points")..] {
        for k in 0..3 {
            assert!(
                p[k] >= bx["min"][k].as_f64().unwrap() && p[k] <= bx["max"][k].as_f64().unwrap()
            );
        }
    }
}

#[test]
fn mesh_files_gzip_f32_and_no_normals() {
    let dir = scratch("mesh");
    ok(
        &dir,
        &["shape", "sphere", "-o", "ball.off", "--resolution", "24"],
    );
    ok(
        &dir,
        &[
            "scan",
            "--mesh",
            "ball.off",
            "-o",
            "out/ball.ply.gz",
            "--no-normals",
            "--precision",
            "f32",
            "--views",
            "3",
            "--truth",
            "out/truth.ply",
        ],
    );
    let cloud = read_points(dir.join("out/ball.ply.gz")).unwrap();
    assert!(cloud.normals.is_none());
    let side = json(&dir.join("out/ball.json"));
    assert_eq!(side["ground_truth_mesh"], "truth.ply");
    assert_eq!(side["ground_truth"]["source"], "ball.off");
    assert_eq!(side["normals"], "none");
    assert_eq!(side["counts"]["total"], cloud.len());
    assert_eq!(
        read_mesh(dir.join("out/truth.ply")).unwrap(),
        read_mesh(dir.join("ball.off")).unwrap()
    );
    for p in &cloud.positions {
        assert!(
            (p.coords.norm() - 1.0).abs() < 0.01,
            "f32 points near the unit sphere"
        );
    }
}

#[test]
fn a_sidecar_is_a_poses_file() {
    let dir = scratch("poses");
    ok(
        &dir,
        &[
            "scan",
            "ellipsoid",
            "-o",
            "a.ply",
            "--views",
            "4",
            "--resolution",
            "40,30",
            "--seed",
            "9",
        ],
    );
    ok(
        &dir,
        &[
            "scan",
            "ellipsoid",
            "-o",
            "b.ply",
            "--poses",
            "a.json",
            "--resolution",
            "40,30",
            "--seed",
            "9",
        ],
    );
    let (a, b) = (
        read_points(dir.join("a.ply")).unwrap(),
        read_points(dir.join("b.ply")).unwrap(),
    );
    assert_eq!(a.len(), b.len());
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((p - q).norm() < 1e-9);
    }
    std::fs::write(dir.join("one.json"), r#"[{"eye": [0, 0, 10]}]"#).unwrap();
    ok(
        &dir,
        &[
            "scan",
            "sphere",
            "-o",
            "top.ply",
            "--poses",
            "one.json",
            "--orthographic",
        ],
    );
    let top = read_points(dir.join("top.ply")).unwrap();
    assert!(
        top.positions.iter().all(|p| p.z > -1e-9),
        "a view from +z sees the upper half only"
    );
    assert_eq!(ply_views(&dir.join("top.ply")).iter().max(), Some(&0));
}

//! Volume recovery on what real scans bring: objects cut by the volume's
//! box, CT in Hounsfield units (negative iso-values, presets, NIfTI
//! `scl_slope`), and results too poor to write.

mod common;

use common::sdf::{noisy_ball_with_rod, recover_quietly, sdf_volume, surface_error, write_raw};
use subdyn::fit::ErrorStats;
use subdyn::fit::recover::{
    RecoverLevel, RecoverParams, RecoverReport, component_cage, poor_result, prepare_volume,
    seed_cage,
};
use subdyn::forces::BoundaryModel;
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real};
use subdyn::subdivision::{RefineOptions, Refiner};
use subdyn::volume::Volume;

/// A ball of radius 10 whose top the box cuts (32³ voxels, centre z = 26,
/// box face z = 31.5): recovered closed, the cap on the face.
#[test]
fn a_ball_cut_by_the_box_closes_on_the_box_face() {
    let c = Point3::new(16.0, 16.0, 26.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p| (p - c).norm() - 10.0);
    let params = RecoverParams {
        boundary: BoundaryModel::Iso { value: 0.5 },
        ..Default::default()
    };
    let prepared = prepare_volume(&vol, &params).unwrap();
    assert_eq!(prepared.smoothed.dims(), [34, 34, 34]);
    let cage = component_cage(&prepared.smoothed, &prepared.smoothed, 0.5, true, None, 12).unwrap();
    let out = recover_quietly(&prepared, &cage.mesh, &cage.boundary, &params);
    assert!(poor_result(&out.report, &params).is_empty());
    let refiner = Refiner::new(&out.control, &RefineOptions::default()).unwrap();
    assert!((0..refiner.level.num_edges()).all(|e| !refiner.level.is_boundary_edge(e)));
    let (tess, _) = tessellate(&refiner, &out.control.positions, 4).unwrap();
    let face = 31.5;
    let rim = (100.0 - (face - c.z) * (face - c.z) as Real).sqrt();
    let cap: Vec<Real> = tess
        .positions
        .iter()
        .filter(|p| p.z > c.z && (p.x - c.x).hypot(p.y - c.y) < rim - 3.0)
        .map(|p| (p.z - face).abs())
        .collect();
    let worst = cap.iter().cloned().fold(0.0, Real::max);
    println!(
        "{} cap points, farthest {worst:.3} voxels from the face",
        cap.len()
    );
    assert!(cap.len() > 100 && worst <= 0.5, "{} {worst}", cap.len());
}

/// With `--open-at-box` the same ball is left open where the box cuts it:
/// one boundary loop, its rim on the box face (within half a voxel).
#[test]
fn open_at_box_leaves_the_cut_open_with_its_rim_on_the_face() {
    let c = Point3::new(16.0, 16.0, 26.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p| (p - c).norm() - 10.0);
    let dir = tempfile::tempdir().unwrap();
    let path = write_raw(dir.path(), "ball", &vol);
    let run = |extra: &[&str]| {
        let mut args = vec!["recover", path.to_str().unwrap(), "--iso", "0.5", "--quiet"];
        args.extend_from_slice(extra);
        common::run_subdyn(dir.path(), &args)
    };
    let out = run(&["-o", "open.obj", "--limit-out", "open.ply", "--open-at-box"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let control = subdyn::io::read_mesh(dir.path().join("open.obj")).unwrap();
    let topo = subdyn::fit::init::surface_topology(&control).unwrap();
    assert_eq!((topo.boundary_loops, topo.components), (1, 1));
    let limit = subdyn::io::read_mesh(dir.path().join("open.ply")).unwrap();
    let rim = boundary_vertices(&limit);
    let worst = rim
        .iter()
        .map(|&v| (limit.positions[v].z - 31.5).abs())
        .fold(0.0, Real::max);
    println!(
        "{} rim vertices, farthest {worst:.3} voxels from the face",
        rim.len()
    );
    assert!(rim.len() > 20 && worst <= 1e-9, "{} {worst}", rim.len());
    // A ball inside the box has nothing to open.
    let inside = sdf_volume([32, 32, 32], [1.0; 3], |p| {
        (p - Point3::new(16.0, 16.0, 16.0)).norm() - 9.0
    });
    let path = write_raw(dir.path(), "inside", &inside);
    let out = common::run_subdyn(
        dir.path(),
        &[
            "recover",
            path.to_str().unwrap(),
            "--iso",
            "0.5",
            "--open-at-box",
            "-o",
            "x.obj",
            "--quiet",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("does not reach the volume's box"), "{err}");
    assert!(!dir.path().join("x.obj").exists());
}

/// Vertices on an edge of only one face.
/// A noisy ball cut by the box, recovered with a quarter voxel of
/// smoothing: the noise tilts some cap faces away from the box face, and
/// removing the others used to leave a vertex where two parts of the
/// surface met at a point ("non-manifold vertex …: its 5 faces form more
/// than one fan", exit 1). Islands inside the opening now go with the cap
/// and the faces round such a vertex stay: the result is one manifold
/// piece with a boundary.
#[test]
fn open_at_box_leaves_a_manifold_when_noise_tilts_cap_faces() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_raw(
        dir.path(),
        "v",
        &sdf_volume([42, 40, 32], [1.0; 3], noisy_ball_with_rod),
    );
    let out = common::run_subdyn(
        dir.path(),
        &[
            "recover",
            path.to_str().unwrap(),
            "--iso",
            "0.5",
            "--sigma",
            "0.25",
            "--open-at-box",
            "-o",
            "open.obj",
            "--quiet",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let control = subdyn::io::read_mesh(dir.path().join("open.obj")).unwrap();
    let topo = subdyn::fit::init::surface_topology(&control).unwrap();
    println!("{topo:?}");
    assert_eq!(topo.components, 1);
    assert!(topo.boundary_loops >= 1);
}

fn boundary_vertices(mesh: &subdyn::mesh::PolyMesh) -> Vec<usize> {
    let mut edges = std::collections::HashMap::new();
    for f in mesh.faces() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut rim: Vec<usize> = edges
        .iter()
        .filter(|(_, n)| **n == 1)
        .flat_map(|((a, b), _)| [*a as usize, *b as usize])
        .collect();
    rim.sort_unstable();
    rim.dedup();
    rim
}

/// A NIfTI-1 int16 volume with `scl_slope`, `scl_inter` (stored =
/// (value − inter) / slope, rounded), unit voxels at the origin.
fn write_int16_nifti(path: &std::path::Path, vol: &Volume, slope: f32, inter: f32) {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let d = vol.dims();
    for (n, v) in [3, d[0], d[1], d[2], 1, 1, 1, 1].iter().enumerate() {
        h[40 + 2 * n..42 + 2 * n].copy_from_slice(&(*v as i16).to_le_bytes());
    }
    h[70..72].copy_from_slice(&4i16.to_le_bytes()); // DT_INT16
    h[72..74].copy_from_slice(&16i16.to_le_bytes());
    for n in 0..4 {
        h[76 + 4 * n..80 + 4 * n].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&slope.to_le_bytes());
    h[116..120].copy_from_slice(&inter.to_le_bytes());
    h[123] = 2; // mm
    h[344..348].copy_from_slice(b"n+1\0");
    for v in vol.data() {
        let stored = ((v - inter) / slope).round() as i16;
        h.extend_from_slice(&stored.to_le_bytes());
    }
    std::fs::write(path, h).unwrap();
}

/// A "CT" ball: air −1000 HU outside, soft tissue 0 HU inside, the
/// surface at −500 HU, stored as int16 with slope 2 and intercept −1024.
/// `--iso` takes negative values as a separate argument, `--preset skin`
/// is −500 HU, and the stored values are rescaled on reading (the preset
/// lies outside the stored range [12, 512]).
#[test]
fn ct_iso_values_may_be_negative_and_presets_are_hounsfield_units() {
    let dir = tempfile::tempdir().unwrap();
    let c = Point3::new(16.0, 16.0, 16.0);
    let sdf = move |p: Point3| (p - c).norm() - 9.0;
    let ramp = sdf_volume([32, 32, 32], [1.0; 3], sdf);
    let hu = ramp
        .with_data(ramp.data().iter().map(|f| -1000.0 + 1000.0 * f).collect())
        .unwrap();
    write_int16_nifti(&dir.path().join("ct.nii"), &hu, 2.0, -1024.0);
    let run = |extra: &[&str], out: &str| {
        let mut args = vec!["recover", "ct.nii", "-o", out, "--quiet"];
        args.extend_from_slice(extra);
        common::run_subdyn(dir.path(), &args)
    };
    let skin = run(&["--preset", "skin"], "skin.obj");
    assert!(
        skin.status.success(),
        "{}",
        String::from_utf8_lossy(&skin.stderr)
    );
    let text = String::from_utf8_lossy(&skin.stdout);
    assert!(text.contains("inside level -500.0000"), "{text}");
    assert!(text.contains("scl_slope 2"), "{text}");
    let shape = subdyn::io::read_mesh(dir.path().join("skin.obj")).unwrap();
    let (max, mean) = surface_error(&shape, sdf);
    assert!(max < 0.5 && mean < 0.15, "max {max} mean {mean}");

    let same = run(&["--iso", "-500"], "iso.obj");
    assert!(same.status.success());
    assert_eq!(
        std::fs::read(dir.path().join("skin.obj")).unwrap(),
        std::fs::read(dir.path().join("iso.obj")).unwrap()
    );
    // −300 HU lies 0.2 voxels inside the −500 surface.
    let deeper = run(&["--iso", "-300"], "deeper.obj");
    assert!(deeper.status.success());
    let shape = subdyn::io::read_mesh(dir.path().join("deeper.obj")).unwrap();
    let (max, _) = surface_error(&shape, move |p| sdf(p) + 0.2);
    assert!(max < 0.5, "{max}");

    let bone = run(&["--preset", "bone"], "bone.obj");
    let err = String::from_utf8_lossy(&bone.stderr);
    assert_eq!(bone.status.code(), Some(1), "{err}");
    assert!(err.contains("iso-value 300 lies outside"), "{err}");
    let both = run(&["--preset", "skin", "--iso", "-500"], "both.obj");
    let err = String::from_utf8_lossy(&both.stderr);
    assert_eq!(both.status.code(), Some(2), "{err}");
    assert!(err.contains("--iso"), "{err}");
    for f in ["bone.obj", "both.obj"] {
        assert!(!dir.path().join(f).exists());
    }
}

/// A model poking out of the box is a poor result: an error naming why, on
/// one line, with nothing written, unless `--accept-poor`.
#[test]
fn a_poor_result_is_an_error_unless_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let c = Point3::new(16.0, 16.0, 16.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p| (p - c).norm() - 9.0);
    let path = write_raw(dir.path(), "ball", &vol);
    // A cage whose limit surface reaches z ≈ 36, four voxels beyond the box.
    let cage = seed_cage(Point3::new(16.0, 16.0, 28.0), 8.0).unwrap();
    subdyn::io::write_mesh(dir.path().join("cage.obj"), &cage, None).unwrap();
    let args = |accept: bool| {
        let mut a = vec![
            "recover",
            path.to_str().unwrap(),
            "--init",
            "cage.obj",
            "--iso",
            "0.5",
            "-o",
            "out.obj",
            "--report",
            "r.json",
            "--quiet",
        ];
        if accept {
            a.push("--accept-poor");
        }
        a
    };
    let out = common::run_subdyn(dir.path(), &args(false));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.lines().count() == 1
            && err.contains("poor result")
            && err.contains("leaves the volume's box")
            && err.contains("--accept-poor"),
        "{err}"
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("unresolved: share of the surface"), "{text}");
    assert!(!dir.path().join("out.obj").exists() && !dir.path().join("r.json").exists());

    let out = common::run_subdyn(dir.path(), &args(true));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("poor result accepted"), "{text}");
    assert!(dir.path().join("out.obj").exists());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(report["dims"], serde_json::json!([32, 32, 32]));
    let why = report["poor_result"]
        .as_array()
        .expect("poor_result in the report");
    assert!(
        why.iter()
            .any(|w| w.as_str().unwrap().contains("leaves the volume's box")),
        "{why:?}"
    );
}

fn level(level: usize, rms: Real, unresolved: Real) -> RecoverLevel {
    RecoverLevel {
        level,
        control_points: 100,
        faces: 98,
        samples: 1000,
        steps: 5,
        cg_iterations: 50,
        seconds: 0.1,
        energy: vec![1.0],
        offsets: ErrorStats::new(&[rms, rms], 30.0),
        unresolved,
        search_voxels: 4.0,
        outside_box: 0.0,
        boundary_points: 0,
        unmatched: 0.0,
    }
}

fn report(levels: Vec<RecoverLevel>, returned_level: usize) -> RecoverReport {
    RecoverReport {
        voxel: 1.0,
        sigma: 0.5,
        inside_level: 0.5,
        smoothing_seconds: 0.0,
        potential_seconds: 0.0,
        levels,
        returned_level,
        converged: false,
        stop_reason: String::new(),
        seconds: 0.1,
    }
}

/// Each way a result can be poor is named; a good one passes.
#[test]
fn poor_results_name_what_is_wrong() {
    let params = RecoverParams::default();
    let good = report(vec![level(0, 0.8, 0.0), level(1, 0.3, 0.005)], 1);
    assert!(poor_result(&good, &params).is_empty());
    let unresolved = report(vec![level(0, 0.8, 0.25)], 0);
    let why = poor_result(&unresolved, &params);
    assert!(
        why.len() == 1 && why[0].contains("25.0 % of the surface found no boundary"),
        "{why:?}"
    );
    let worse = report(vec![level(0, 0.3, 0.0), level(1, 0.9, 0.02)], 0);
    let why = poor_result(&worse, &params);
    assert!(
        why.len() == 1 && why[0].contains("level 1 followed the image worse than level 0"),
        "{why:?}"
    );
    let mut outside = level(0, 0.3, 0.0);
    outside.outside_box = 0.02;
    let why = poor_result(&report(vec![outside], 0), &params);
    assert!(
        why.len() == 1 && why[0].contains("20 of its 1000 samples"),
        "{why:?}"
    );
}

/// The MNI152 T1 brain cut by the box below z index 60 (through the
/// temporal lobes and the cerebellum), at `--iso 85.5`: closed, every
/// limit point inside the box and the cap within half a voxel of the face;
/// with `--open-at-box` open, one boundary loop with its rim on the face and
/// the whole cross-section open (no cap face left more than 3 voxels in from
/// the rim).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn the_mni_brain_cut_by_the_box_closes_or_opens_on_the_face() {
    let mni = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/volumes/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz");
    let full = subdyn::io::read_volume(&mni, &Default::default())
        .unwrap()
        .volume;
    let [nx, ny, nz] = full.dims();
    let cut = 60;
    let data = full.data()[nx * ny * cut..].to_vec();
    let vol = Volume::new([nx, ny, nz - cut], data, [1.0; 3], Point3::origin()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = write_raw(dir.path(), "brain", &vol);
    let face = -0.5;
    for open in [false, true] {
        let mut args = vec![
            "recover",
            path.to_str().unwrap(),
            "--iso",
            "85.5",
            "-o",
            "b.obj",
            "--limit-out",
            "b.ply",
            "--quiet",
        ];
        if open {
            args.push("--open-at-box");
        }
        let out = common::run_subdyn(dir.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let control = subdyn::io::read_mesh(dir.path().join("b.obj")).unwrap();
        let topo = subdyn::fit::init::surface_topology(&control).unwrap();
        let limit = subdyn::io::read_mesh(dir.path().join("b.ply")).unwrap();
        let lowest = limit
            .positions
            .iter()
            .map(|p| p.z)
            .fold(Real::MAX, Real::min);
        let near = |p: &Point3| p.z < face + 0.5;
        println!(
            "open {open}: {:?}; lowest limit z {lowest:.3} (face {face}); {} limit points within 0.5 voxel",
            (topo.boundary_loops, topo.components, topo.genus),
            limit.positions.iter().filter(|p| near(p)).count()
        );
        assert!(
            lowest >= face - 0.5,
            "the surface leaves the box: z {lowest}"
        );
        if !open {
            assert_eq!((topo.boundary_loops, topo.components), (0, 1));
            assert!(limit.positions.iter().filter(|p| near(p)).count() > 1000);
            continue;
        }
        assert_eq!((topo.boundary_loops, topo.components), (1, 1));
        let rim = boundary_vertices(&limit);
        let worst = rim
            .iter()
            .map(|&v| (limit.positions[v].z - face).abs())
            .fold(0.0, Real::max);
        assert!(rim.len() > 100 && worst <= 1e-9, "{} {worst}", rim.len());
        // No cap left: limit points on the face lie within 3 voxels of the rim.
        let rim_points: Vec<Point3> = rim.iter().map(|&v| limit.positions[v]).collect();
        let stray = limit
            .positions
            .iter()
            .filter(|p| p.z < face + 0.25)
            .filter(|p| rim_points.iter().all(|r| (r - *p).norm() > 3.0))
            .count();
        assert_eq!(stray, 0, "{stray} limit points of a cap left on the face");
    }
}

/// A raw volume whose sidecar names the surface's level (`iso_value`, as
/// data-gen writes): without `--iso` the recovery takes that level set, with
/// a note; `--iso` overrides it. The ball's intensity falls linearly from 1
/// at radius 7 to 0 at radius 11, so level 0.25 is the sphere of radius 10
/// and level 0.5 that of radius 9.
#[test]
fn a_sidecars_iso_value_is_the_default_boundary() {
    let dir = tempfile::tempdir().unwrap();
    let c = Point3::new(16.0, 16.0, 16.0);
    let vol = sdf_volume([32, 32, 32], [1.0; 3], move |p| {
        ((p - c).norm() - 9.0) / 4.0
    });
    write_raw(dir.path(), "ball", &vol);
    let side = dir.path().join("ball.json");
    let mut header: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    header["iso_value"] = serde_json::json!(0.25);
    std::fs::write(&side, header.to_string()).unwrap();
    let mean_radius = |extra: &[&str], out: &str| {
        let mut args = vec!["recover", "ball.json", "-o", out];
        args.extend_from_slice(extra);
        let run = common::run_subdyn(dir.path(), &args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let shape = subdyn::io::read_mesh(dir.path().join(out)).unwrap();
        let (_, mean) = surface_error(&shape, move |p| (p - c).norm());
        (mean, String::from_utf8_lossy(&run.stdout).into_owned())
    };
    let (r, text) = mean_radius(&[], "default.obj");
    assert!((r - 10.0).abs() < 0.2, "mean radius {r}\n{text}");
    assert!(text.contains("iso-value 0.25 from the sidecar"), "{text}");
    let (r, text) = mean_radius(&["--iso", "0.5"], "given.obj");
    assert!((r - 9.0).abs() < 0.2, "mean radius {r}\n{text}");
    assert!(!text.contains("from the sidecar"), "{text}");
}

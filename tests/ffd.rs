//! Free-form deformation with Catmull-Clark volume lattices (MacCracken &
//! Joy 1996): identity, affine invariance, the cube's exact region, local
//! updates, type-n cells, convergence to the tricubic B-spline volume.

mod common;

use common::Rng;
use common::volume::pyramid;
use common::volume::tricubic;
use subdyn::ffd::{Enclosing, Ffd, FfdParams, LayeredFfd};
use subdyn::lattice::{Lattice, box_grid, cylinder, locally_refined};
use subdyn::math::{Point3, Vector3, bbox_diagonal, bounding_box};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn params(levels: usize) -> FfdParams {
    FfdParams {
        levels,
        ..Default::default()
    }
}

fn random_points(rng: &mut Rng, lat: &Lattice, n: usize) -> Vec<Point3> {
    let (lo, hi) = bounding_box(&lat.positions).unwrap();
    (0..n)
        .map(|_| {
            p(
                rng.uniform(lo.x, hi.x),
                rng.uniform(lo.y, hi.y),
                rng.uniform(lo.z, hi.z),
            )
        })
        .collect()
}

fn lattices() -> Vec<(&'static str, Lattice)> {
    let mut rng = Rng::new(5);
    let mut grid = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.0), [2, 2, 2]).unwrap();
    for q in &mut grid.positions {
        q.coords += 0.08 * rng.vector();
    }
    // Local refinement: the centre cell of a 3³ grid, whose neighbours
    // become cells with valence-4 face points and valence-2 edge points.
    let big = box_grid(p(0.0, 0.0, 0.0), p(1.5, 1.5, 1.5), [3, 3, 3]).unwrap();
    let (local, _) = locally_refined(&big, &[13]).unwrap();
    vec![
        ("grid", grid),
        ("cylinder", cylinder(1.0, 1.0, 5, 1).unwrap()),
        ("pyramid", pyramid()),
        ("local", local),
    ]
}

#[test]
fn an_unmoved_lattice_leaves_every_vertex_in_place() {
    let mut rng = Rng::new(1);
    for (name, lat) in lattices() {
        let pts = random_points(&mut rng, &lat, 2000);
        let ffd = Ffd::new(&lat, &pts, &params(2)).unwrap();
        let d = bbox_diagonal(&pts);
        assert!(
            ffd.report.embedded > 300,
            "{name}: only {} embedded",
            ffd.report.embedded
        );
        assert_eq!(ffd.report.embedded + ffd.report.outside, pts.len());
        for (i, (a, b)) in ffd.deformed.iter().zip(&pts).enumerate() {
            assert!(
                (a - b).norm() < 1e-10 * d,
                "{name}: vertex {i} moved by {}",
                (a - b).norm()
            );
        }
        if name == "pyramid" || name == "local" {
            assert!(ffd.report.in_type_n_cells > 0, "no point in a type-4 cell");
        }
    }
}

#[test]
fn an_affine_lattice_map_moves_the_model_by_the_same_map() {
    let mut rng = Rng::new(2);
    for (name, lat) in lattices() {
        let pts = random_points(&mut rng, &lat, 1000);
        let ffd = Ffd::new(&lat, &pts, &params(2)).unwrap();
        let (a, b) = common::random_affine(&mut rng);
        let moved = ffd.deform(&common::affine(&lat.positions, &a, &b)).unwrap();
        let expect = common::affine(&pts, &a, &b);
        let d = bbox_diagonal(&expect);
        let outside: std::collections::HashSet<u32> = ffd.outside.iter().copied().collect();
        for i in 0..pts.len() {
            let want = if outside.contains(&(i as u32)) {
                pts[i]
            } else {
                expect[i]
            };
            let err = (moved[i] - want).norm();
            assert!(err < 1e-10 * d, "{name}: vertex {i} off by {err}");
        }
    }
}

#[test]
fn a_cube_lattice_deforms_exactly_the_cube() {
    let lat = box_grid(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut rng = Rng::new(3);
    let inside: Vec<Point3> = (0..3000)
        .map(|_| p(rng.next_f64(), rng.next_f64(), rng.next_f64()))
        .collect();
    // Points just outside one face of the cube.
    let outside: Vec<Point3> = (0..600)
        .map(|i| {
            let mut q = p(rng.next_f64(), rng.next_f64(), rng.next_f64());
            let k = i % 3;
            q[k] = if i % 2 == 0 { -1e-4 } else { 1.0 + 1e-4 };
            q
        })
        .collect();
    for levels in 1..=3 {
        let ffd = Ffd::new(&lat, &inside, &params(levels)).unwrap();
        assert_eq!(
            ffd.report.outside, 0,
            "level {levels}: cube points left out"
        );
        let ffd = Ffd::new(&lat, &outside, &params(levels)).unwrap();
        assert_eq!(
            ffd.report.embedded, 0,
            "level {levels}: points outside the cube embedded"
        );
    }
}

#[test]
fn moving_control_points_updates_only_their_columns_and_matches_the_full_product() {
    let lat = cylinder(1.0, 2.0, 6, 2).unwrap();
    let mut rng = Rng::new(4);
    let pts = random_points(&mut rng, &lat, 3000);
    let mut ffd = Ffd::new(&lat, &pts, &params(2)).unwrap();
    let mut control = lat.positions.clone();
    let mut total = 0;
    for step in 0..5 {
        let c = rng.below(control.len());
        let q = control[c] + 0.3 * rng.vector();
        control[c] = q;
        let touched = ffd.move_control(&[(c, q)]).unwrap();
        assert_eq!(touched, ffd.bt.row(c).0.len());
        total += touched;
        let full = ffd.deform(&control).unwrap();
        let err = common::max_pairwise(&full, &ffd.deformed);
        assert!(err < 1e-12, "step {step}: local update differs by {err}");
    }
    assert!(
        total < 5 * ffd.report.embedded,
        "local updates touched {total} rows"
    );
    assert!(ffd.move_control(&[(10_000, p(0.0, 0.0, 0.0))]).is_err());
    assert!(ffd.move_control(&[(0, p(f64::NAN, 0.0, 0.0))]).is_err());
}

/// On a regular grid, the FFD converges to the tricubic B-spline volume of
/// the moved control points as the level grows (interior cells only, whose
/// refinement uses the uniform rules). Prints the error table.
#[test]
fn ffd_converges_to_the_tricubic_bspline_volume_on_a_regular_grid() {
    let n = [4usize, 4, 4];
    let lat = box_grid(p(0.0, 0.0, 0.0), p(4.0, 4.0, 4.0), n).unwrap();
    let mut rng = Rng::new(9);
    let moved: Vec<Point3> = lat
        .positions
        .iter()
        .map(|q| q + 0.4 * rng.vector())
        .collect();
    // In [1, 3]³ the undeformed tricubic volume is the identity (linear precision).
    let pts: Vec<Point3> = (0..400)
        .map(|_| {
            p(
                rng.uniform(1.0, 3.0),
                rng.uniform(1.0, 3.0),
                rng.uniform(1.0, 3.0),
            )
        })
        .collect();
    let exact: Vec<Point3> = pts
        .iter()
        .map(|q| tricubic(&moved, n, [q.x, q.y, q.z]))
        .collect();
    let mut errors = Vec::new();
    for levels in 1..=4 {
        let ffd = Ffd::new(&lat, &pts, &params(levels)).unwrap();
        assert_eq!(ffd.report.outside, 0);
        let got = ffd.deform(&moved).unwrap();
        let err = common::max_pairwise(&got, &exact);
        println!("n = {levels}: max |FFD − tricubic| = {err:.3e}");
        errors.push(err);
    }
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 3.0, "error did not drop fourfold: {errors:?}");
    }
}

#[test]
fn bad_inputs_are_refused() {
    let lat = box_grid(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let pts = vec![p(0.5, 0.5, 0.5)];
    assert!(Ffd::new(&lat, &pts, &params(0)).is_err());
    assert!(Ffd::new(&lat, &pts, &params(7)).is_err());
    assert!(Ffd::new(&lat, &[p(f64::NAN, 0.0, 0.0)], &params(1)).is_err());
    let ffd = Ffd::new(&lat, &pts, &params(1)).unwrap();
    assert!(ffd.deform(&lat.positions[..7]).is_err());
    let mut nan = lat.positions.clone();
    nan[2].z = f64::INFINITY;
    assert!(ffd.deform(&nan).is_err());
}

// ---------------------------------------------------------------- CLI

mod cli {
    use std::path::Path;
    use std::process::{Command, Output};

    use subdyn::ffd::{Ffd, FfdParams};
    use subdyn::io::write_lattice;
    use subdyn::lattice::box_grid;
    use subdyn::math::Point3;

    fn subdyn(dir: &Path, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_subdyn"))
            .args(args)
            .current_dir(dir)
            .output()
            .expect("the subdyn binary runs")
    }

    fn stderr(out: &Output) -> String {
        String::from_utf8_lossy(&out.stderr).into_owned()
    }

    /// Exit 1, one `subdyn: error:` line holding `needle`, no output file.
    fn assert_clean_failure(dir: &Path, out: &Output, needle: &str) {
        let err = stderr(out);
        assert_eq!(out.status.code(), Some(1), "stderr: {err}");
        assert_eq!(err.lines().count(), 1, "one line expected: {err}");
        assert!(
            err.starts_with("subdyn: error: ") && !err.contains("panicked"),
            "{err}"
        );
        assert!(
            err.to_lowercase().contains(&needle.to_lowercase()),
            "`{needle}` not in: {err}"
        );
        assert!(!dir.join("out.obj").exists(), "output written on failure");
        let temp = std::fs::read_dir(dir)
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().contains(".tmp."));
        assert!(!temp, "temporary file left behind");
    }

    /// A cube of side 0.6 centred in the unit cube, plus one vertex outside.
    const MODEL: &str = "v 0.2 0.2 0.2\nv 0.8 0.2 0.2\nv 0.8 0.8 0.2\nv 0.2 0.8 0.2\n\
v 0.2 0.2 0.8\nv 0.8 0.2 0.8\nv 0.8 0.8 0.8\nv 0.2 0.8 0.8\nv 3 3 3\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nf 9 1 2\n";

    fn obj_vertices(path: &Path) -> Vec<Point3> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
                Point3::new(c[0], c[1], c[2])
            })
            .collect()
    }

    #[test]
    fn ffd_with_moves_and_with_a_deformed_lattice() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("model.obj"), MODEL).unwrap();
        let lat = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [2, 2, 2]).unwrap();
        write_lattice(d.join("lat.json"), &lat).unwrap();
        let top = lat.num_vertices() - 1;
        std::fs::write(
            d.join("moves.json"),
            format!("{{\"moves\": [{{\"vertex\": {top}, \"offset\": [0, 0, 0.5]}}]}}"),
        )
        .unwrap();
        let out = subdyn(
            d,
            &[
                "ffd",
                "model.obj",
                "--lattice",
                "lat.json",
                "--moves",
                "moves.json",
                "--levels",
                "2",
                "-o",
                "out.obj",
                "--report",
                "r.json",
                "--quiet",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
        assert_eq!(report["ffd"]["outside"], 1);
        assert_eq!(report["ffd"]["embedded"], 8);
        // Same as the library.
        let model = subdyn::io::read_mesh(d.join("model.obj")).unwrap();
        let ffd = Ffd::new(
            &lat,
            &model.positions,
            &FfdParams {
                levels: 2,
                ..Default::default()
            },
        )
        .unwrap();
        let mut moved = lat.positions.clone();
        moved[top].z += 0.5;
        let want = ffd.deform(&moved).unwrap();
        let got = obj_vertices(&d.join("out.obj"));
        assert_eq!(got.len(), 9);
        for (a, b) in got.iter().zip(&want) {
            assert!((a - b).norm() < 1e-9, "{a:?} vs {b:?}");
        }
        assert!(
            got[6].z > 0.8 + 1e-3,
            "the corner near the moved control point rose"
        );
        assert_eq!(got[8], Point3::new(3.0, 3.0, 3.0));
        // The same deformation given as a whole deformed lattice.
        let mut lat2 = lat.clone();
        lat2.positions = moved;
        write_lattice(d.join("lat2.json"), &lat2).unwrap();
        let out = subdyn(
            d,
            &[
                "ffd",
                "model.obj",
                "--lattice",
                "lat.json",
                "--deformed",
                "lat2.json",
                "--levels",
                "2",
                "-o",
                "out2.obj",
                "--quiet",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let got2 = obj_vertices(&d.join("out2.obj"));
        for (a, b) in got2.iter().zip(&got) {
            assert!((a - b).norm() < 1e-9);
        }
    }

    #[test]
    fn ffd_bad_inputs_fail_with_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("model.obj"), MODEL).unwrap();
        let lat = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
        write_lattice(d.join("lat.json"), &lat).unwrap();
        let big = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [2, 1, 1]).unwrap();
        write_lattice(d.join("big.json"), &big).unwrap();
        std::fs::write(
            d.join("broken.json"),
            "{\"vertices\": [[0, 0, 0],\n [1, 0 0]]}",
        )
        .unwrap();
        let flat = "{\"vertices\": [[0,0,0],[1,0,0],[1,1,0],[0,1,0],[0,0,0],[1,0,0],[1,1,0],[0,1,0.0000000000001]], \
                    \"hexahedra\": [[0,1,2,3,4,5,6,7]]}";
        std::fs::write(d.join("flat.json"), flat).unwrap();
        std::fs::write(
            d.join("far.json"),
            "{\"moves\": [{\"vertex\": 99, \"offset\": [0, 0, 1]}]}",
        )
        .unwrap();
        std::fs::write(
            d.join("nan.json"),
            "{\"moves\": [{\"vertex\": 1, \"offset\": [NaN, 0, 1]}]}",
        )
        .unwrap();
        std::fs::write(d.join("both.json"), "{\"moves\": [{\"vertex\": 1}]}").unwrap();
        let run = |lattice: &str, extra: &[&str]| {
            let mut args = vec!["ffd", "model.obj", "--lattice", lattice, "-o", "out.obj"];
            args.extend_from_slice(extra);
            if !extra.contains(&"--levels") {
                args.extend_from_slice(&["--levels", "1"]);
            }
            subdyn(d, &args)
        };
        assert_clean_failure(
            d,
            &run("broken.json", &["--deformed", "lat.json"]),
            "broken.json:2",
        );
        assert_clean_failure(
            d,
            &run("flat.json", &["--deformed", "lat.json"]),
            "degenerate",
        );
        assert_clean_failure(
            d,
            &run("lat.json", &["--deformed", "big.json"]),
            "not the same lattice",
        );
        assert_clean_failure(
            d,
            &run("lat.json", &["--moves", "far.json"]),
            "vertex 99 does not exist",
        );
        assert_clean_failure(d, &run("lat.json", &["--moves", "nan.json"]), "nan.json:1");
        assert_clean_failure(
            d,
            &run("lat.json", &["--moves", "both.json"]),
            "exactly one",
        );
        assert_clean_failure(
            d,
            &run("lat.json", &["--moves", "far.json", "--levels", "9"]),
            "--levels 9",
        );
    }
}

#[test]
fn bench_ffd_local_updates_match_the_full_product() {
    let dir = tempfile::tempdir().unwrap();
    let out = common::run_subdyn(
        dir.path(),
        &[
            "bench",
            "ffd",
            "--vertices",
            "3000",
            "--octree-levels",
            "1",
            "--levels",
            "2",
            "--updates",
            "20",
            "--quiet",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let last = text.lines().last().expect("some output");
    let json: serde_json::Value = serde_json::from_str(last).expect("the last line is JSON");
    // A torus inside its own bounding box: every vertex is embedded.
    assert_eq!(json["embedded"], json["vertices"], "{last}");
    assert_eq!(json["outside"], 0, "{last}");
    assert!(
        json["max_abs_diff_local_vs_full"].as_f64().unwrap() < 1e-12,
        "{last}"
    );
    // The 32³-cell refined lattice: 4³ cells refined three times.
    assert_eq!(json["refined_32_cells"], 32768, "{last}");
    let bytes = json["refined_32_topology_bytes"].as_u64().unwrap();
    assert!(
        bytes > 8 * json["refined_32_compact_bytes"].as_u64().unwrap(),
        "{last}"
    );
    for key in ["refine_s", "embed_s", "local_update_ms", "full_product_ms"] {
        assert!(
            json[key].as_f64().is_some_and(|s| s > 0.0),
            "{key} in {last}"
        );
    }
    let bad = common::run_subdyn(dir.path(), &["bench", "ffd", "--levels", "9"]);
    assert_eq!(bad.status.code(), Some(1));
}

// ------------------------------------------------ hierarchical deformation

fn inner_points(rng: &mut Rng, lo: Point3, hi: Point3, n: usize) -> Vec<Point3> {
    (0..n)
        .map(|_| {
            p(
                rng.uniform(lo.x, hi.x),
                rng.uniform(lo.y, hi.y),
                rng.uniform(lo.z, hi.z),
            )
        })
        .collect()
}

fn max_gap(a: &[Point3], b: &[Point3]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// A coarse 2×1×1 lattice deformed non-affinely, then its octree
/// subdivision: the finer layer carries a non-zero correction.
fn coarse_then_fine(rng: &mut Rng) -> (Vec<Point3>, LayeredFfd, LayeredFfd) {
    let lat = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.0), [2, 1, 1]).unwrap();
    let pts = inner_points(rng, p(0.1, 0.1, 0.1), p(1.9, 0.9, 0.9), 400);
    let mut coarse = LayeredFfd::global(lat.clone(), &pts, &params(2)).unwrap();
    coarse.control[4] += Vector3::new(0.1, 0.2, 0.3);
    coarse.control[9] -= Vector3::new(0.0, 0.25, 0.1);
    let fine = coarse.finer(&params(2)).unwrap();
    (pts, coarse, fine)
}

#[test]
fn global_to_local_keeps_the_model_and_corrects_only_the_non_affine_gap() {
    let mut rng = Rng::new(21);
    let lat = box_grid(p(0.0, 0.0, 0.0), p(2.0, 1.0, 1.0), [2, 1, 1]).unwrap();
    let pts = inner_points(&mut rng, p(0.1, 0.1, 0.1), p(1.9, 0.9, 0.9), 400);
    let d = bbox_diagonal(&pts);
    let mut g = LayeredFfd::global(lat.clone(), &pts, &params(2)).unwrap();
    assert!(g.max_correction() < 1e-12 * d);
    assert!(max_gap(&g.model().unwrap(), &pts) < 1e-10 * d);
    // An affine global deformation: octree and Catmull-Clark rules agree, no correction.
    let (a, b) = common::random_affine(&mut rng);
    g.control = common::affine(&lat.positions, &a, &b);
    let before = g.model().unwrap();
    let fine = g.finer(&params(2)).unwrap();
    assert_eq!(fine.ffd.report.outside, 0);
    assert!(
        fine.max_correction() < 1e-10 * d,
        "{}",
        fine.max_correction()
    );
    assert!(max_gap(&fine.model().unwrap(), &before) < 1e-10 * d);
    // A non-affine one: the gap is real and the correction removes it.
    let (pts2, coarse, fine) = coarse_then_fine(&mut rng);
    let before = coarse.model().unwrap();
    assert!(max_gap(&before, &pts2) > 0.05);
    assert!(
        fine.max_correction() > 1e-3 * d,
        "{}",
        fine.max_correction()
    );
    assert!(max_gap(&fine.model().unwrap(), &before) < 1e-10 * d);
    // A local move on the finer lattice moves exactly the vertices of its
    // column of B, each by its weight times the move.
    let c = (0..fine.control.len())
        .max_by_key(|&c| fine.ffd.bt.row(c).0.len())
        .unwrap();
    let delta = Vector3::new(0.0, 0.0, 0.2);
    let mut moved = fine.clone();
    moved.control[c] += delta;
    let after = moved.model().unwrap();
    let (rows, w) = fine.ffd.bt.row(c);
    assert!(!rows.is_empty());
    let mut expect = before.clone();
    for (&r, &w) in rows.iter().zip(w) {
        expect[r as usize] += w * delta;
    }
    assert!(max_gap(&after, &expect) < 1e-10 * d);
}

#[test]
fn local_to_global_carries_the_model_and_the_fine_lattice() {
    let mut rng = Rng::new(22);
    let (_, _, mut fine) = coarse_then_fine(&mut rng);
    fine.control[30] += Vector3::new(0.05, -0.1, 0.1); // a local edit
    let model = fine.model().unwrap();
    let d = bbox_diagonal(&model);
    let enc = Enclosing::around(
        &fine,
        &subdyn::lattice::BoxLatticeParams::default(),
        &params(2),
    )
    .unwrap();
    assert_eq!(enc.ffd.report.outside, 0);
    let (m, c) = enc.carried(&enc.lattice.positions).unwrap();
    assert!(max_gap(&m, &model) < 1e-10 * d);
    assert!(max_gap(&c, &fine.control) < 1e-10 * d);
    // An affine global edit moves both by the same map, and back in local
    // mode the correction is the old one turned by the linear part.
    let (a, b) = common::random_affine(&mut rng);
    let moved = common::affine(&enc.lattice.positions, &a, &b);
    let (m, c) = enc.carried(&moved).unwrap();
    assert!(max_gap(&m, &common::affine(&model, &a, &b)) < 1e-9 * d);
    assert!(max_gap(&c, &common::affine(&fine.control, &a, &b)) < 1e-9 * d);
    let back = enc.back_to_local(&fine, &moved).unwrap();
    assert!(max_gap(&back.model().unwrap(), &m) < 1e-10 * d);
    for (new, old) in back.correction.iter().zip(&fine.correction) {
        assert!((new - a * old).norm() < 1e-9 * d);
    }
    // A non-affine global edit: the fine lattice bends with the model.
    let mut bent = enc.lattice.positions.clone();
    bent[0] += Vector3::new(0.0, 0.0, -0.4);
    let (m, c) = enc.carried(&bent).unwrap();
    assert!(max_gap(&m, &model) > 1e-3 && max_gap(&c, &fine.control) > 1e-3);
    assert!(enc.back_to_local(&fine, &[]).is_err());
}

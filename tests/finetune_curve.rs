//! Curve subdivision and curve fine tuning (issue 8, curve half): stencil
//! rows, B-spline reproduction under refinement, the exact fine-tuned curve
//! `Q' = α P'`, the closed-curve spring model (energy decrease, closure,
//! identity), the energy gradient, and bad input.

mod common;

use std::f64::consts::TAU;

use common::Rng;
use subdyn::finetune::{
    CurveFinetune, CurveFinetuneParams, ScalarFunction, SpringTargets, ValuesOn, alpha_from_values,
    exact_finetune, values_on,
};
use subdyn::math::{Point3, Vector3};
use subdyn::subdivision::{CurveScheme, CurveTopology};

const SCHEMES: [CurveScheme; 2] = [CurveScheme::Quadratic, CurveScheme::Cubic];

fn random_points(rng: &mut Rng, n: usize, planar: bool) -> Vec<Point3> {
    (0..n)
        .map(|_| {
            let v = rng.vector();
            Point3::new(v.x, v.y, if planar { 0.0 } else { v.z })
        })
        .collect()
}

/// A closed polygon around an ellipse (planar), slightly perturbed.
fn ellipse(rng: &mut Rng, n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            Point3::new(2.0 * a.cos() + 0.05 * rng.uniform(-1.0, 1.0), a.sin(), 0.0)
        })
        .collect()
}

fn eval(topo: &CurveTopology, pts: &[Point3], t: f64, der: usize) -> Vector3 {
    let s = topo.limit_stencil(&[t], der).unwrap();
    s.apply(pts).unwrap()[0].coords
}

fn params_in(topo: &CurveTopology, count: usize) -> Vec<f64> {
    let s = topo.num_spans() as f64;
    (0..=count).map(|i| s * i as f64 / count as f64).collect()
}

fn element_count(topo: &CurveTopology, k: usize) -> usize {
    match values_on(topo.degree(), k).0 {
        ValuesOn::Edges => topo.num_legs(),
        ValuesOn::Vertices => topo.num_points,
    }
}

#[test]
fn refinement_rows_sum_to_one_and_reproduce_the_b_spline() {
    let mut rng = Rng::new(7);
    for scheme in SCHEMES {
        for closed in [false, true] {
            let topo = CurveTopology::new(scheme, 7, closed).unwrap();
            let pts = random_points(&mut rng, 7, false);
            let (fine, s) = topo.refine_levels(2).unwrap();
            assert_eq!(s.num_rows(), fine.num_points);
            assert_eq!(fine.num_spans(), 4 * topo.num_spans());
            for w in s.row_sums() {
                assert!((w - 1.0).abs() < 1e-14, "{scheme:?} row sum {w}");
            }
            let fine_pts = s.apply(&pts).unwrap();
            for t in params_in(&topo, 37) {
                for der in 0..=2 {
                    let a = eval(&topo, &pts, t, der);
                    let b = eval(&fine, &fine_pts, 4.0 * t, der) * 4f64.powi(der as i32);
                    assert!(
                        (a - b).norm() < 1e-11,
                        "{scheme:?} closed={closed} t={t} der={der}: {a} vs {b}"
                    );
                }
            }
            // Limit rows: positions sum to 1, derivatives to 0.
            let lim = topo.limit_stencil(&params_in(&topo, 11), 1).unwrap();
            assert!(lim.row_sums().iter().all(|w| w.abs() < 1e-13));
            let lim = topo.limit_stencil(&params_in(&topo, 11), 0).unwrap();
            assert!(lim.row_sums().iter().all(|w| (w - 1.0).abs() < 1e-14));
        }
    }
}

#[test]
fn refined_polygons_converge_to_the_limit_curve() {
    let mut rng = Rng::new(3);
    for scheme in SCHEMES {
        let topo = CurveTopology::new(scheme, 6, true).unwrap();
        let pts = random_points(&mut rng, 6, true);
        let (fine, s) = topo.refine_levels(6).unwrap();
        let fine_pts = s.apply(&pts).unwrap();
        // Every refined point is within a small distance of the limit curve.
        let limit = topo
            .limit_stencil(&params_in(&topo, 4000), 0)
            .unwrap()
            .apply(&pts)
            .unwrap();
        let worst = fine_pts
            .iter()
            .map(|p| {
                limit
                    .iter()
                    .map(|q| (p - q).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(worst < 2e-3, "{scheme:?}: {worst}");
        assert_eq!(fine.num_points, 6 * 64);
    }
}

#[test]
fn linear_alpha_takes_its_control_values_at_the_element_abscissae() {
    for (scheme, on) in [
        (CurveScheme::Quadratic, "edges"),
        (CurveScheme::Cubic, "vertices"),
    ] {
        let topo = CurveTopology::new(scheme, 6, true).unwrap();
        let values = [1.0, 1.5, 0.7, 2.0, 1.1, 0.9];
        let alpha = alpha_from_values(&topo, 1, &values).unwrap();
        for (e, v) in values.iter().enumerate() {
            // Edge e of a quadratic curve sits at t = e; vertex v of a cubic at t = v − 1.
            let t = if scheme == CurveScheme::Quadratic {
                e as f64
            } else {
                e as f64 - 1.0
            };
            let a = alpha.value(&topo, t).unwrap();
            assert!((a - v).abs() < 1e-14, "{on}: element {e} α={a} value={v}");
        }
    }
}

#[test]
fn exact_curve_satisfies_q_prime_equals_alpha_p_prime() {
    let mut rng = Rng::new(11);
    for scheme in SCHEMES {
        for k in 1..=3 {
            for closed in [false, true] {
                let n = 8;
                let topo = CurveTopology::new(scheme, n, closed).unwrap();
                let pts = random_points(&mut rng, n, false);
                let values: Vec<f64> = (0..element_count(&topo, k))
                    .map(|_| rng.uniform(0.5, 2.0))
                    .collect();
                let alpha = alpha_from_values(&topo, k, &values).unwrap();
                let q = exact_finetune(&topo, &pts, &alpha).unwrap();
                assert_eq!(q.degree, k + topo.degree());
                let dq = q.curve.derivative_curve().unwrap();
                let (t0, t1) = q.curve.domain();
                assert_eq!((t0, t1), (0.0, topo.num_spans() as f64));
                assert!((q.curve.point(0.0).coords - eval(&topo, &pts, 0.0, 0)).norm() < 1e-12);
                for t in params_in(&topo, 101) {
                    let want = alpha.value(&topo, t).unwrap() * eval(&topo, &pts, t, 1);
                    let got = dq.point(t).coords;
                    assert!(
                        (got - want).norm() < 1e-12 * (1.0 + want.norm()),
                        "{scheme:?} k={k} closed={closed} t={t}: {got} vs {want}"
                    );
                }
                if closed {
                    let end = q.curve.point(t1) - q.curve.point(t0);
                    assert!((end - q.gap).norm() < 1e-12);
                    assert_eq!(q.periodic_points.len(), n * q.multiplicity);
                }
            }
        }
    }
}

#[test]
fn constant_alpha_scales_an_open_curve_about_its_start() {
    let mut rng = Rng::new(5);
    for scheme in SCHEMES {
        for k in 1..=3 {
            let topo = CurveTopology::new(scheme, 7, false).unwrap();
            let pts = random_points(&mut rng, 7, false);
            for c in [1.0, 1.7] {
                let alpha = ScalarFunction::constant(&topo, k, c).unwrap();
                let tuner =
                    CurveFinetune::new(&topo, &pts, &alpha, &CurveFinetuneParams::default())
                        .unwrap();
                let (curve, report) = tuner.solve().unwrap();
                assert_eq!(report.iterations, 0);
                let p0 = eval(&topo, &pts, 0.0, 0);
                for t in params_in(&topo, 53) {
                    let want = p0 + c * (eval(&topo, &pts, t, 0) - p0);
                    let got = curve.point(t).coords;
                    assert!((got - want).norm() < 1e-12, "{scheme:?} k={k} c={c} t={t}");
                }
            }
        }
    }
}

#[test]
fn identity_alpha_leaves_a_closed_curve_unchanged() {
    let mut rng = Rng::new(9);
    for scheme in SCHEMES {
        for k in 1..=3 {
            let topo = CurveTopology::new(scheme, 9, true).unwrap();
            let pts = ellipse(&mut rng, 9);
            let alpha = ScalarFunction::constant(&topo, k, 1.0).unwrap();
            let tuner =
                CurveFinetune::new(&topo, &pts, &alpha, &CurveFinetuneParams::default()).unwrap();
            let (curve, report) = tuner.solve().unwrap();
            assert!(
                report.converged && report.final_energy < 1e-20,
                "{report:?}"
            );
            for t in params_in(&topo, 71) {
                let d = (curve.point(t).coords - eval(&topo, &pts, t, 0)).norm();
                assert!(d < 1e-10, "{scheme:?} k={k} t={t}: {d}");
            }
        }
    }
}

#[test]
fn constant_alpha_on_a_closed_curve_scales_it_about_the_fixed_point() {
    let mut rng = Rng::new(13);
    for scheme in SCHEMES {
        let k = 1;
        let topo = CurveTopology::new(scheme, 8, true).unwrap();
        let pts = ellipse(&mut rng, 8);
        let c = 1.4;
        let alpha = ScalarFunction::constant(&topo, k, c).unwrap();
        // The fixed control point of Q is P's control point 0 written in Q's space.
        let identity = ScalarFunction::constant(&topo, k, 1.0).unwrap();
        let fixed = exact_finetune(&topo, &pts, &identity)
            .unwrap()
            .periodic_points[0];
        let tuner =
            CurveFinetune::new(&topo, &pts, &alpha, &CurveFinetuneParams::default()).unwrap();
        let (curve, report) = tuner.solve().unwrap();
        assert!(report.initial_energy > 1e-3, "{report:?}");
        assert!(report.final_energy < 1e-12, "{report:?}");
        for t in params_in(&topo, 61) {
            let want = fixed.coords + c * (eval(&topo, &pts, t, 0) - fixed.coords);
            let d = (curve.point(t).coords - want).norm();
            assert!(d < 1e-6, "{scheme:?} t={t}: {d}");
        }
    }
}

#[test]
fn stretched_leg_energy_decreases_and_the_curve_closes() {
    let mut rng = Rng::new(17);
    for scheme in SCHEMES {
        for k in 1..=3 {
            let topo = CurveTopology::new(scheme, 8, true).unwrap();
            let pts = ellipse(&mut rng, 8);
            let mut values = vec![1.0; element_count(&topo, k)];
            values[2] = 1.5;
            let alpha = alpha_from_values(&topo, k, &values).unwrap();
            let tuner =
                CurveFinetune::new(&topo, &pts, &alpha, &CurveFinetuneParams::default()).unwrap();
            let (curve, r) = tuner.solve().unwrap();
            let label = format!("{scheme:?} k={k}");
            eprintln!(
                "{label}: {} after {} iterations, |grad| {:.1e}, E {:.3e} -> {:.3e}",
                r.termination, r.iterations, r.gradient_norm, r.initial_energy, r.final_energy
            );
            assert!(
                r.converged && r.gradient_norm < 1e-6,
                "{label}: {} {} {}",
                r.termination,
                r.iterations,
                r.gradient_norm
            );
            assert!(
                r.iterations > 1 && r.energies.len() == r.iterations + 1,
                "{label}"
            );
            for w in r.energies.windows(2) {
                assert!(
                    w[1] <= w[0] + 1e-15 * r.energies[0],
                    "{label}: energy rose {w:?}"
                );
            }
            assert!(r.final_energy < 0.5 * r.initial_energy, "{label}: {r:?}");
            assert!(
                r.gap_before > 1e-3,
                "{label}: the exact curve should not close: {}",
                r.gap_before
            );
            assert!(r.gap_after < 1e-8, "{label}: gap {}", r.gap_after);
            // Tangent continuity across the seam.
            let (t0, t1) = curve.domain();
            let (a, b) = (curve.tangent(t0).unwrap(), curve.tangent(t1).unwrap());
            assert!((a - b).norm() < 1e-9 * a.norm(), "{label}: {a} vs {b}");
        }
    }
}

#[test]
fn a_non_planar_closed_curve_closes_too() {
    let mut rng = Rng::new(19);
    let topo = CurveTopology::new(CurveScheme::Cubic, 8, true).unwrap();
    let pts: Vec<Point3> = ellipse(&mut rng, 8)
        .iter()
        .enumerate()
        .map(|(i, p)| Point3::new(p.x, p.y, 0.5 * (TAU * i as f64 / 8.0).sin()))
        .collect();
    let mut values = vec![1.0; 8];
    values[3] = 1.4;
    let alpha = alpha_from_values(&topo, 1, &values).unwrap();
    let tuner = CurveFinetune::new(&topo, &pts, &alpha, &CurveFinetuneParams::default()).unwrap();
    let (curve, r) = tuner.solve().unwrap();
    eprintln!(
        "3-D: {} after {} iterations, |grad| {:.1e}",
        r.termination, r.iterations, r.gradient_norm
    );
    assert!(
        r.energies
            .windows(2)
            .all(|w| w[1] <= w[0] + 1e-15 * r.energies[0])
    );
    assert!(
        r.final_energy < 0.5 * r.initial_energy && r.gradient_norm < 1e-6,
        "{}",
        r.termination
    );
    assert!(r.gap_before > 1e-3 && r.gap_after < 1e-8);
    // The result really leaves the plane.
    assert!(curve.samples(200).iter().any(|p| p.z.abs() > 0.1));
}

#[test]
fn energy_gradient_matches_finite_differences() {
    let mut rng = Rng::new(21);
    for planar in [true, false] {
        let pts = random_points(&mut rng, 7, planar);
        let legs: Vec<Vector3> = (0..7).map(|_| rng.vector()).collect();
        let mut targets = SpringTargets::from_legs(&legs, 1.0, 2.0, planar);
        targets.lengths.iter_mut().for_each(|l| *l *= 1.3);
        let mut g = vec![Vector3::zeros(); pts.len()];
        let e = targets.energy(&pts, Some(&mut g));
        assert!(e > 0.0);
        let h = 1e-6;
        for i in 0..pts.len() {
            for c in 0..if planar { 2 } else { 3 } {
                let (mut a, mut b) = (pts.clone(), pts.clone());
                a[i][c] += h;
                b[i][c] -= h;
                let fd = (targets.energy(&a, None) - targets.energy(&b, None)) / (2.0 * h);
                assert!(
                    (fd - g[i][c]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "planar={planar} {i},{c}: {fd} vs {}",
                    g[i][c]
                );
            }
        }
    }
}

#[test]
fn bad_input_is_one_clear_error() {
    let quad = CurveScheme::Quadratic;
    assert!(CurveTopology::new(quad, 2, false).is_err());
    assert!(CurveTopology::new(CurveScheme::Cubic, 2, true).is_err());
    let topo = CurveTopology::new(quad, 5, true).unwrap();
    assert!(topo.locate(f64::NAN).is_err());
    let open = CurveTopology::new(quad, 5, false).unwrap();
    assert!(open.locate(3.5).is_err());
    for (k, values) in [
        (1, vec![1.0; 4]),
        (1, vec![1.0, f64::NAN, 1.0, 1.0, 1.0]),
        (1, vec![1.0, -1.0, 1.0, 1.0, 1.0]),
        (4, vec![1.0; 5]),
        (0, vec![1.0; 5]),
    ] {
        let err = alpha_from_values(&topo, k, &values).unwrap_err();
        assert!(matches!(err, subdyn::Error::Input(_)), "{err}");
    }
    let alpha = ScalarFunction::constant(&topo, 1, 1.2).unwrap();
    let good: Vec<Point3> = (0..5)
        .map(|i| Point3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    let p = CurveFinetuneParams::default();
    let mut nan = good.clone();
    nan[3].x = f64::NAN;
    assert!(CurveFinetune::new(&topo, &nan, &alpha, &p).is_err());
    assert!(CurveFinetune::new(&topo, &[Point3::origin(); 5], &alpha, &p).is_err());
    assert!(CurveFinetune::new(&topo, &good[..4], &alpha, &p).is_err());
    let far = CurveFinetuneParams {
        fixed_point: 1000,
        ..p.clone()
    };
    assert!(CurveFinetune::new(&topo, &good, &alpha, &far).is_err());
    let bad_k = CurveFinetuneParams {
        k_angle: f64::NAN,
        ..p.clone()
    };
    assert!(CurveFinetune::new(&topo, &good, &alpha, &bad_k).is_err());
    let open_alpha = ScalarFunction::constant(&open, 1, 1.0).unwrap();
    assert!(CurveFinetune::new(&topo, &good, &open_alpha, &p).is_err());
}

// ---------------------------------------------------------------------------
// The `subdyn finetune curve` verb.

mod cli {
    use super::common::run_subdyn as subdyn;

    const OCTAGON: &str = r#"{"scheme": "quadratic", "closed": true,
        "points": [[0,0],[2,0],[3,1],[3,3],[2,4],[0,4],[-1,3],[-1,1]]}"#;
    const VALUES: &str = r#"{"degree": 1, "values": [1.5, 1, 1, 1, 1, 1, 1, 1]}"#;

    #[test]
    fn finetune_curve_writes_the_curve_report_and_picture() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("c.json"), OCTAGON).unwrap();
        std::fs::write(dir.path().join("v.json"), VALUES).unwrap();
        let out = subdyn(
            dir.path(),
            &[
                "finetune", "curve", "c.json", "--values", "v.json", "-o", "q.json", "--report",
                "r.json", "--png", "q.png",
            ],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let q: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("q.json")).unwrap())
                .unwrap();
        assert_eq!(q["degree"], 3);
        assert_eq!(q["closed"], true);
        let n = q["control_points"].as_array().unwrap().len();
        assert_eq!(q["knots"].as_array().unwrap().len(), n + 4);
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap())
                .unwrap();
        assert!(r["gap_after"].as_f64().unwrap() < 1e-8);
        assert!(r["final_energy"].as_f64().unwrap() < r["initial_energy"].as_f64().unwrap());
        assert!(std::fs::metadata(dir.path().join("q.png")).unwrap().len() > 1000);
    }

    #[test]
    fn bad_curve_input_is_one_line_and_no_output() {
        let cases: [(&str, &str, &str, &[&str]); 7] = [
            (
                "{\"scheme\": \"quadratic\",\n \"points\": [[0,0],[1,",
                VALUES,
                "c.json:2",
                &[],
            ),
            (
                r#"{"scheme": "quintic", "points": [[0,0],[1,0],[1,1]]}"#,
                VALUES,
                "quadratic",
                &[],
            ),
            (
                r#"{"scheme": "cubic", "closed": true, "points": [[0,0],[1,0]]}"#,
                VALUES,
                "control points",
                &[],
            ),
            (
                r#"{"scheme": "cubic", "points": [[0,0],[1,0,2,3],[1,1],[0,1]]}"#,
                VALUES,
                "point 1",
                &[],
            ),
            (
                OCTAGON,
                r#"{"degree": 1, "values": [1, 1]}"#,
                "expected 8",
                &[],
            ),
            (
                OCTAGON,
                r#"{"degree": 1, "values": [1, 1, 1, -2, 1, 1, 1, 1]}"#,
                "positive",
                &[],
            ),
            (OCTAGON, VALUES, "--k", &["--k", "1,nan"]),
        ];
        for (curve, values, needle, extra) in cases {
            let dir = tempfile::tempdir().unwrap();
            std::fs::write(dir.path().join("c.json"), curve).unwrap();
            std::fs::write(dir.path().join("v.json"), values).unwrap();
            let mut args = vec![
                "finetune", "curve", "c.json", "--values", "v.json", "-o", "q.json", "--png",
                "q.png",
            ];
            args.extend_from_slice(extra);
            let out = subdyn(dir.path(), &args);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{needle}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
            assert!(
                err.starts_with("subdyn: error:") && err.contains(needle),
                "{needle}: {err}"
            );
            let left: Vec<_> = std::fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect();
            assert_eq!(left.len(), 2, "{needle}: files left {left:?}");
        }
    }
}

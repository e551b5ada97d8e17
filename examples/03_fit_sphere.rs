//! Fit a noisy sphere scan starting from a cube cage (development check).
use subdyn::fit::*;
use subdyn::math::*;
use subdyn::mesh::PointCloud;
fn main() {
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(10000);
    let noise = 0.001 * 2.0 * 3f64.sqrt();
    let pts: Vec<Point3> = (0..n)
        .map(|_| {
            let z = 2.0 * rnd() - 1.0;
            let t = std::f64::consts::TAU * rnd();
            let r = (1.0 - z * z).sqrt();
            let g =
                ((-2.0 * rnd().max(1e-300).ln()).sqrt()) * (std::f64::consts::TAU * rnd()).cos();
            let p = Vector3::new(r * t.cos(), r * t.sin(), z);
            Point3::from(p * (1.0 + noise * g))
        })
        .collect();
    let cloud = PointCloud::new(pts, None).unwrap();
    let mut cube = subdyn::examples::cube();
    for p in &mut cube.positions {
        *p = Point3::from((p.coords - Vector3::new(0.5, 0.5, 0.5)) * 2.0);
    }
    let t = std::time::Instant::now();
    let res = fit_point_cloud(&cloud, &cube, &FitParams::default(), &mut |l, s, e| {
        eprintln!("level {l} step {s} energy {e:.6e}")
    })
    .unwrap();
    for l in &res.report.levels {
        println!(
            "level {} cps {} steps {} cg {} {:.2}s  max {:.3}% p95 {:.3}% rms {:.4}% mean {:.4}%",
            l.level,
            l.control_points,
            l.steps,
            l.cg_iterations,
            l.seconds,
            l.error.max_pct,
            l.error.p95_pct,
            l.error.rms_pct,
            l.error.mean_pct
        );
    }
    // true error: distance of limit surface samples to unit sphere
    let r = subdyn::subdivision::Refiner::new(&res.control, &Default::default()).unwrap();
    let (tess, _) = subdyn::limit::tessellate(&r, &res.control.positions, 4).unwrap();
    let dev = tess
        .positions
        .iter()
        .map(|p| (p.coords.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    let mean = tess
        .positions
        .iter()
        .map(|p| (p.coords.norm() - 1.0).abs())
        .sum::<f64>()
        / tess.positions.len() as f64;
    println!(
        "{} ; total {:.2}s; surface vs truth: max {:.4}% mean {:.4}% of diag",
        res.report.stop_reason,
        t.elapsed().as_secs_f64(),
        100.0 * dev / (2.0 * 3f64.sqrt()),
        100.0 * mean / (2.0 * 3f64.sqrt())
    );
}

//! Curve fine tuning end to end on a 100-leg closed quadratic curve (a wavy
//! ring, linear α with one leg at 1.5): exact product and integral, spring
//! setup and the solve, by Levenberg-Marquardt (the default) and by argmin's
//! nonlinear CG (the earlier default, the before-figure). Baseline in the
//! same run: the exact open-curve fine tuning of the same polygon (no
//! optimisation).
//! Run with `cargo bench --bench finetune_curve`.

use std::f64::consts::TAU;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use subdyn::finetune::{CurveFinetuneParams, FinetuneMethod, alpha_from_values, finetune_curve};
use subdyn::math::Point3;
use subdyn::subdivision::{CurveScheme, CurveTopology};

fn ring(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            let r = 1.0 + 0.1 * (5.0 * a).sin();
            Point3::new(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let n = 100;
    let points = ring(n);
    let params = CurveFinetuneParams::default();
    let ncg = CurveFinetuneParams {
        method: FinetuneMethod::NonlinearCg,
        ..Default::default()
    };
    let closed = CurveTopology::new(CurveScheme::Quadratic, n, true).unwrap();
    let mut values = vec![1.0; closed.num_legs()];
    values[0] = 1.5;
    let alpha = alpha_from_values(&closed, 1, &values).unwrap();
    for p in [&params, &ncg] {
        let (_, report) = finetune_curve(&closed, &points, &alpha, p).unwrap();
        eprintln!(
            "closed 100 legs, {:?}: {} variables, {} iterations ({}), |grad| {:.1e}, energy {:.3e} -> {:.6e}, gap {:.3} -> {:.1e}",
            p.method,
            report.num_variables,
            report.iterations,
            report.termination,
            report.gradient_norm,
            report.initial_energy,
            report.final_energy,
            report.gap_before,
            report.gap_after
        );
    }
    let open = CurveTopology::new(CurveScheme::Quadratic, n, false).unwrap();
    let open_alpha = alpha_from_values(&open, 1, &values[..open.num_legs()]).unwrap();
    let mut group = c.benchmark_group("finetune_curve");
    group.sample_size(10);
    group.bench_function("open_100_exact", |b| {
        b.iter(|| finetune_curve(&open, black_box(&points), &open_alpha, &params).unwrap())
    });
    group.bench_function("closed_100_spring_lm", |b| {
        b.iter(|| finetune_curve(&closed, black_box(&points), &alpha, &params).unwrap())
    });
    group.bench_function("closed_100_spring_ncg", |b| {
        b.iter(|| finetune_curve(&closed, black_box(&points), &alpha, &ncg).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Criterion bench of surface fine tuning end to end on a 1,000-edge
//! Doo-Sabin mesh (issue 8's goal: under 100 ms), with baselines measured
//! in the same run: Levenberg-Marquardt factoring every step
//! (`refinement_iterations: 0`, the earlier solver's linear algebra), the
//! precompute alone (conversion, loops, targets) and one energy-and-gradient
//! evaluation. The printed lines give each run's phase timings
//! (`LmTimings`).
//!
//! Inputs: `subdyn::examples::torus(20, 25, 2.0, 0.7)` (500 quads, 1,000
//! edges) read as a Doo-Sabin mesh; the 25 edges of one meridian get control
//! value 1.3, the vertices of the opposite meridian are fixed. Timed with
//! the default Levenberg-Marquardt solver to its stopping rules, and with
//! argmin's nonlinear CG (the earlier default, the before-figure) capped at
//! 200 iterations: it does not reach its stopping rules within 2,000
//! iterations, so its figure is the cost of 200 iterations, not of a
//! converged run (the printed lines give both runs' final energies). The
//! cube of example 32 is timed with both as well. Outputs: criterion's
//! timings. Run with `cargo bench --bench finetune_surface`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use subdyn::finetune::{FinetuneMethod, SurfaceFineTune, SurfaceFineTuneParams, SurfaceScheme};

fn fine_tuning(c: &mut Criterion) {
    let (n, m) = (20usize, 25usize);
    let mesh = subdyn::examples::torus(n, m, 2.0, 0.7);
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let values: Vec<(u32, u32, f64)> = (0..m).map(|j| (id(0, j), id(0, j + 1), 1.3)).collect();
    let fixed: Vec<u32> = (0..m).map(|j| id(n / 2, j)).collect();
    let params = SurfaceFineTuneParams::default();
    let every_step = SurfaceFineTuneParams {
        refinement_iterations: 0,
        ..Default::default()
    };
    let ncg = SurfaceFineTuneParams {
        max_iters: 200,
        method: FinetuneMethod::NonlinearCg,
        ..Default::default()
    };
    let ncg_full = SurfaceFineTuneParams {
        method: FinetuneMethod::NonlinearCg,
        ..Default::default()
    };
    let problem = SurfaceFineTune::new(&mesh, SurfaceScheme::DooSabin, &values, &fixed, &params)
        .expect("a torus is a valid Doo-Sabin mesh");
    for p in [&params, &every_step, &ncg, &ncg_full] {
        let run = SurfaceFineTune::new(&mesh, SurfaceScheme::DooSabin, &values, &fixed, p)
            .expect("precompute");
        let (_, report) = run.solve().expect("solve");
        eprintln!(
            "1,000-edge torus, {:?} (refinement {}), at most {} iterations: {} converted vertices, {} iterations ({}), energy {:.3e} -> {:.12e}, {:.3} s, {:?}",
            p.method,
            p.refinement_iterations,
            p.max_iters,
            problem.mesh.num_vertices(),
            report.iterations,
            report.termination,
            report.energies[0],
            report.energies.last().copied().unwrap_or(0.0),
            report.seconds[1],
            report.solver_timings
        );
    }
    let x: Vec<_> = problem.mesh.positions.clone();

    let mut group = c.benchmark_group("finetune_surface_torus_1000_edges");
    group.sample_size(10);
    let cube = subdyn::examples::cube();
    let cube_values = [(7, 3, 1.3), (7, 5, 1.3), (7, 6, 1.3)];
    let cube_fixed = [0, 1, 4];
    let torus_case = (&mesh, &values[..], &fixed[..]);
    let cube_case = (&cube, &cube_values[..], &cube_fixed[..]);
    for (name, (m, v, f), p) in [
        ("end_to_end_lm", torus_case, &params),
        ("end_to_end_lm_factor_every_step", torus_case, &every_step),
        ("end_to_end_ncg_200_iters", torus_case, &ncg),
        ("cube_converged_lm", cube_case, &params),
        ("cube_converged_ncg", cube_case, &ncg_full),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let p = SurfaceFineTune::new(black_box(m), SurfaceScheme::DooSabin, v, f, p)
                    .expect("precompute");
                p.solve().expect("solve")
            })
        });
    }
    group.bench_function("precompute_only", |b| {
        b.iter(|| {
            SurfaceFineTune::new(
                black_box(&mesh),
                SurfaceScheme::DooSabin,
                &values,
                &fixed,
                &params,
            )
        })
    });
    group.bench_function("energy_and_gradient", |b| {
        b.iter(|| problem.energy.energy_and_gradient(black_box(&x), true))
    });
    group.finish();
}

criterion_group!(benches, fine_tuning);
criterion_main!(benches);

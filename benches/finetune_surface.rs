//! Criterion bench of surface fine tuning end to end on a 1,000-edge
//! Doo-Sabin mesh (issue 8's goal: under 100 ms), with two baselines measured
//! in the same run: the precompute alone (conversion, loops, targets) and one
//! energy-and-gradient evaluation.
//!
//! Inputs: `subdyn::examples::torus(20, 25, 2.0, 0.7)` (500 quads, 1,000
//! edges) read as a Doo-Sabin mesh; the 25 edges of one meridian get control
//! value 1.3, the vertices of the opposite meridian are fixed. The solve is
//! capped at 200 iterations: on this mesh the nonlinear CG does not reach its
//! stopping rules within 2,000 iterations (see the report), so the figure is
//! the cost of 200 iterations, not of a converged run. A coarse case that
//! does converge (the cube of example 32) is timed as well. Outputs:
//! criterion's timings. Run with `cargo bench --bench finetune_surface`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use subdyn::finetune::{SurfaceFineTune, SurfaceFineTuneParams, SurfaceScheme};

fn fine_tuning(c: &mut Criterion) {
    let (n, m) = (20usize, 25usize);
    let mesh = subdyn::examples::torus(n, m, 2.0, 0.7);
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let values: Vec<(u32, u32, f64)> = (0..m).map(|j| (id(0, j), id(0, j + 1), 1.3)).collect();
    let fixed: Vec<u32> = (0..m).map(|j| id(n / 2, j)).collect();
    let params = SurfaceFineTuneParams {
        max_iters: 200,
        ..Default::default()
    };
    let problem = SurfaceFineTune::new(&mesh, SurfaceScheme::DooSabin, &values, &fixed, &params)
        .expect("a torus is a valid Doo-Sabin mesh");
    let (_, report) = problem.solve().expect("solve");
    eprintln!(
        "1,000-edge torus: {} converted vertices, {} iterations ({}), energy {:.3e} -> {:.3e}",
        problem.mesh.num_vertices(),
        report.iterations,
        report.termination,
        report.energies[0],
        report.energies.last().copied().unwrap_or(0.0)
    );
    let x: Vec<_> = problem.mesh.positions.clone();

    let mut group = c.benchmark_group("finetune_surface_torus_1000_edges");
    group.sample_size(10);
    group.bench_function("end_to_end", |b| {
        b.iter(|| {
            let p = SurfaceFineTune::new(
                black_box(&mesh),
                SurfaceScheme::DooSabin,
                &values,
                &fixed,
                &params,
            )
            .expect("precompute");
            p.solve().expect("solve")
        })
    });
    let cube = subdyn::examples::cube();
    let cube_values = [(7, 3, 1.3), (7, 5, 1.3), (7, 6, 1.3)];
    let defaults = SurfaceFineTuneParams::default();
    group.bench_function("cube_converged_end_to_end", |b| {
        b.iter(|| {
            let p = SurfaceFineTune::new(
                black_box(&cube),
                SurfaceScheme::DooSabin,
                &cube_values,
                &[0, 1, 4],
                &defaults,
            )
            .expect("precompute");
            p.solve().expect("solve")
        })
    });
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

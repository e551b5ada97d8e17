//! Criterion benches of uniform Catmull-Clark refinement of a quad torus:
//! topology refinement, stencil build (per level, composed) and stencil
//! application (composed table vs level by level).
//!
//! Inputs: `subdyn::examples::torus(64, 64, 1.0, 0.3)` refined to level 2
//! (65,536 faces). Outputs: criterion's timings. For the full-size comparison
//! with OpenSubdiv use `subdyn bench subdivide` (316×316, level 2).
//!
//! Run with `cargo bench --bench subdivide`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use subdyn::math::Point3;
use subdyn::stencil::StencilTable;
use subdyn::subdivision::{RefineOptions, Refiner, refine_stencil, refine_topology};

const GRID: usize = 64;
const LEVELS: usize = 2;

fn refinement(c: &mut Criterion) {
    let mesh = subdyn::examples::torus(GRID, GRID, 1.0, 0.3);
    let refiner = Refiner::new(&mesh, &RefineOptions::default()).expect("a torus is valid");
    let hierarchy = refiner.refine_uniform(LEVELS).expect("two levels");
    let composed = hierarchy.stencil_to_level(LEVELS).expect("levels exist");

    let mut group = c.benchmark_group(format!("torus{GRID}_level{LEVELS}"));
    group.sample_size(20);
    group.bench_function("topology", |b| {
        b.iter(|| Refiner::new(black_box(&mesh), &RefineOptions::default()))
    });
    group.bench_function("refine_topology", |b| {
        b.iter(|| {
            let l1 = refine_topology(black_box(&refiner.level));
            refine_topology(&l1)
        })
    });
    group.bench_function("stencil_build", |b| {
        b.iter(|| {
            let mut sharp = refiner.sharpness.clone();
            let mut tables: Vec<StencilTable> = Vec::new();
            for k in 0..LEVELS {
                let (t, next) = refine_stencil(
                    &hierarchy.levels[k],
                    &sharp,
                    &hierarchy.levels[k + 1],
                    false,
                );
                tables.push(t);
                sharp = next;
            }
            tables[1].compose(&tables[0])
        })
    });
    let mut out = vec![Point3::origin(); composed.num_rows()];
    group.bench_function("stencil_apply", |b| {
        b.iter(|| composed.apply_into(black_box(&mesh.positions), &mut out))
    });
    let mut l1 = vec![Point3::origin(); hierarchy.stencils[0].num_rows()];
    let mut l2 = vec![Point3::origin(); hierarchy.stencils[1].num_rows()];
    group.bench_function("apply_levelwise", |b| {
        b.iter(|| {
            hierarchy.stencils[0].apply_into(black_box(&mesh.positions), &mut l1);
            hierarchy.stencils[1].apply_into(&l1, &mut l2);
        })
    });
    group.finish();
}

criterion_group!(benches, refinement);
criterion_main!(benches);

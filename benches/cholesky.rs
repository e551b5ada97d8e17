//! `linalg`'s scalar sparse Cholesky (`SparseCholesky`, the dynamics'
//! implicit steps) against faer's sparse `Llt` on one thread, on weighted
//! grid Laplacians plus a diagonal (the SPD systems of `tests/linalg_cholesky.rs`)
//! of 1,024, 10,000 and 62,500 unknowns: the whole factorisation (ordering,
//! symbolic analysis and numeric factor), a numeric refactorisation on the
//! same pattern, and a solve with three right-hand sides (x, y, z).
//! Run with `cargo bench --bench cholesky`; the figures go to
//! `src/linalg/mod.rs`'s doc.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Par, Side};

use subdyn::linalg::SparseCholesky;
use subdyn::math::{Point3, Real};
use subdyn::stencil::StencilTable;

/// `A = Σ_e w_e (e_a − e_b)(e_a − e_b)ᵀ + diag(c)` on a `w × w` grid (right
/// and upper neighbours), as `(row, column, value)` entries, both triangles.
fn grid(w: usize) -> Vec<(usize, usize, Real)> {
    let n = w * w;
    let mut diagonal: Vec<Real> = (0..n)
        .map(|i| 0.35 + 0.25 * (1.7 * i as Real).cos())
        .collect();
    let mut out = Vec::new();
    for i in 0..w {
        for j in 0..w {
            let a = i * w + j;
            let near = [(i + 1 < w).then(|| a + w), (j + 1 < w).then(|| a + 1)];
            for b in near.into_iter().flatten() {
                let weight = 1.0 + 0.5 * ((a * 31 + b * 17) as Real).sin();
                out.push((a, b, -weight));
                out.push((b, a, -weight));
                diagonal[a] += weight;
                diagonal[b] += weight;
            }
        }
    }
    out.extend(diagonal.into_iter().enumerate().map(|(i, d)| (i, i, d)));
    out
}

fn bench(c: &mut Criterion) {
    faer::set_global_parallelism(Par::Seq);
    let mut group = c.benchmark_group("cholesky");
    group.sample_size(10);
    for w in [32, 100, 250] {
        let n = w * w;
        let entries = grid(w);
        let mut rows = vec![Vec::new(); n];
        for &(r, col, v) in &entries {
            rows[r].push((col as u32, v));
        }
        let table = StencilTable::from_rows(n, &rows);
        let triplets: Vec<Triplet<usize, usize, Real>> = entries
            .iter()
            .map(|&(r, col, v)| Triplet::new(r, col, v))
            .collect();
        let matrix = SparseColMat::<usize, Real>::try_new_from_triplets(n, n, &triplets).unwrap();
        let points: Vec<Point3> = (0..n)
            .map(|i| Point3::new((0.37 * i as Real).sin(), 1.0, (0.11 * i as Real).cos()))
            .collect();
        let rhs = Mat::from_fn(n, 3, |i, k| points[i][k]);

        group.bench_with_input(BenchmarkId::new("subdyn factor", n), &n, |b, _| {
            b.iter(|| black_box(SparseCholesky::new(&table).unwrap()))
        });
        group.bench_with_input(BenchmarkId::new("faer factor", n), &n, |b, _| {
            b.iter(|| black_box(matrix.as_ref().sp_cholesky(Side::Lower).unwrap()))
        });
        let mut ours = SparseCholesky::new(&table).unwrap();
        group.bench_with_input(BenchmarkId::new("subdyn refactor", n), &n, |b, _| {
            b.iter(|| ours.refactor(&table).unwrap())
        });
        let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).unwrap();
        group.bench_with_input(BenchmarkId::new("faer refactor", n), &n, |b, _| {
            b.iter(|| {
                black_box(
                    Llt::try_new_with_symbolic(symbolic.clone(), matrix.as_ref(), Side::Lower)
                        .unwrap(),
                )
            })
        });
        let theirs = matrix.as_ref().sp_cholesky(Side::Lower).unwrap();
        group.bench_with_input(BenchmarkId::new("subdyn solve", n), &n, |b, _| {
            b.iter(|| black_box(ours.solve(&points).unwrap()))
        });
        group.bench_with_input(BenchmarkId::new("faer solve", n), &n, |b, _| {
            b.iter(|| black_box(theirs.solve(&rhs)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

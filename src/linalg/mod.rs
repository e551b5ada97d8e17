//! Linear algebra written once for the whole crate: the conjugate-gradient
//! loop ([`cg`]) with its preconditioners; the fill-reducing orderings
//! (nested dissection with minimum degree on small parts); and one sparse
//! Cholesky `P A Pᵀ = L Lᵀ`: a symbolic phase (`symbolic`: ordering,
//! elimination tree, row patterns by `ereach`) feeding two up-looking
//! numeric factors, scalar entries over a [`StencilTable`](crate::stencil::StencilTable)
//! ([`SparseCholesky`], `cholesky`, the dynamics' implicit steps) and 3 × 3
//! blocks split between two threads at the first separator
//! ([`CholeskyPattern`], [`Cholesky`], `block_cholesky`, fine tuning's
//! Gauss-Newton systems); Levenberg-Marquardt on a sparse Gauss-Newton
//! matrix ([`levenberg_marquardt`]) with its steps after the first solved by
//! CG preconditioned with an earlier factor ([`preconditioned_solution`]).
//!
//! `tests/linalg_cholesky.rs` checks both factors against faer's sparse
//! `Llt` (a dev-dependency only) on grid Laplacians of 300 and 625 unknowns
//! (and their `⊗ S₃` block forms): the solutions agree to `1e-10` relative.
//! `benches/cholesky.rs` times the scalar factor against faer's `Llt`, both
//! on one thread, on such grids (2026-12-07, a 2-core AMD EPYC, criterion
//! medians; 1,024 / 10,000 / 62,500 unknowns): the whole factorisation
//! (ordering, analysis, numeric) 0.88 / 21.4 / 178 ms against faer's 0.52 /
//! 10.8 / 70 ms; a numeric refactorisation on the same pattern (what the
//! implicit steps repeat) 0.19 / 6.0 / 93 ms against 0.14 / 5.3 / 41 ms; a
//! solve with three right-hand sides 0.031 / 0.46 / 6.6 ms against 0.030 /
//! 0.45 / 12.2 ms. So faer factors faster at every size (1.1–2.5 ×) and ours
//! solves as fast, twice as fast at the largest size; the dynamics' systems
//! (a few thousand control points, factored once and solved many times) sit
//! at the small end. The block factor's timing is in `block_cholesky`'s docs
//! (faer 0.24 on the benchmark torus system).

mod block_cholesky;
pub mod cg;
mod cholesky;
mod levenberg_marquardt;
mod min_degree;
mod nested_dissection;
mod refined_step;
mod symbolic;

pub use block_cholesky::{Cholesky, CholeskyPattern};
pub use cg::{CgBreakdown, CgElement, CgOutcome, CgStop, Jacobi, Preconditioner, cg};
pub use cholesky::SparseCholesky;
pub use levenberg_marquardt::{
    FORCING_MAX, LeastSquares, LmParams, LmRun, LmTimings, REFINEMENT_ITERATIONS, Residuals,
    levenberg_marquardt,
};
pub(crate) use nested_dissection::nested_dissection;
pub use refined_step::{RELATIVE_RESIDUAL, preconditioned_solution};

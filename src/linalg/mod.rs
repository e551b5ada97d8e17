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

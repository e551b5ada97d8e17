//! Linear algebra written once for the whole crate: the conjugate-gradient
//! loop ([`cg`]) with its preconditioners; the fill-reducing orderings
//! (nested dissection with minimum degree on small parts); and one sparse
//! Cholesky `P A Pᵀ = L Lᵀ`: a symbolic phase (`symbolic`: ordering,
//! elimination tree, row patterns by `ereach`) feeding two up-looking
//! numeric factors, scalar entries over a [`StencilTable`](crate::stencil::StencilTable)
//! ([`SparseCholesky`], `cholesky`, the dynamics' implicit steps) and 3 × 3
//! blocks split between two threads at the first separator
//! ([`CholeskyPattern`], [`Cholesky`], `block_cholesky`, fine tuning's
//! Gauss-Newton systems).

mod block_cholesky;
pub mod cg;
mod cholesky;
mod min_degree;
mod nested_dissection;
mod symbolic;

pub(crate) use block_cholesky::join_if;
pub use block_cholesky::{Cholesky, CholeskyPattern};
pub use cg::{CgBreakdown, CgElement, CgOutcome, CgStop, Jacobi, Preconditioner, cg};
pub use cholesky::SparseCholesky;
pub(crate) use nested_dissection::nested_dissection;

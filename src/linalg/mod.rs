//! Linear algebra written once for the whole crate: the conjugate-gradient
//! loop ([`cg`]) with its preconditioners, and the fill-reducing orderings
//! (nested dissection with minimum degree on small parts) that both sparse
//! Choleskys (`dynamics::cholesky`, `finetune::sparse_cholesky`) use.

pub mod cg;
mod min_degree;
mod nested_dissection;

pub use cg::{CgBreakdown, CgElement, CgOutcome, CgStop, Jacobi, Preconditioner, cg};
pub(crate) use nested_dissection::nested_dissection;

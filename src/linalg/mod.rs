//! Linear algebra written once for the whole crate: the conjugate-gradient
//! loop ([`cg`]) with its preconditioners.

pub mod cg;

pub use cg::{CgBreakdown, CgElement, CgOutcome, CgStop, Jacobi, Preconditioner, cg};

//! A Levenberg-Marquardt step from an earlier factorisation: conjugate
//! gradients ([`crate::linalg::cg`]) on `A x = b` preconditioned by the
//! Cholesky factor of an earlier `A`.
//!
//! Between Levenberg-Marquardt iterations the sparsity pattern of
//! `A = H + λ D` is fixed and its values change little, so the previous
//! factor `M = L Lᵀ ≈ A` makes `M⁻¹ A` close to the identity and a few
//! iterations (one triangular solve pair and one product with `A` each)
//! reach the solution to [`RELATIVE_RESIDUAL`]; that is cheaper than a new
//! numeric factorisation. When it does not converge within the allowed
//! iterations the caller factors `A` afresh.

use crate::math::Real;

use super::block_cholesky::{Cholesky, CholeskyPattern};
use super::cg::{CgStop, Preconditioner, cg};

/// The tightest convergence asked of a step: `|b − A x| ≤ RELATIVE_RESIDUAL
/// · |b|`, `1e-10` (a direct solve of these systems leaves about `1e-13`).
pub const RELATIVE_RESIDUAL: Real = 1e-10;

/// The solution of `A x = b`, `A` given by `values` in `pattern`'s slots,
/// by conjugate gradients preconditioned by `factor` (of another matrix of
/// the same pattern), to `|b − A x| ≤ relative · |b|` (`relative` at least
/// [`RELATIVE_RESIDUAL`]) with at most `max_iterations` iterations; `None`
/// if it did not converge or met a direction of non-positive curvature. The
/// second value is the number of iterations done.
pub fn preconditioned_solution(
    pattern: &CholeskyPattern,
    values: &[Real],
    factor: &Cholesky<'_>,
    b: &[Real],
    relative: Real,
    max_iterations: usize,
) -> (Option<Vec<Real>>, usize) {
    let mut x = vec![0.0; b.len()];
    let stop = CgStop {
        tolerance: relative.max(RELATIVE_RESIDUAL),
        max_iterations,
    };
    match cg(|p| Ok(pattern.product(values, p)), factor, b, &mut x, &stop) {
        Ok(Ok(outcome)) if outcome.converged => (Some(x), outcome.iterations[0]),
        Ok(Ok(_)) => (None, max_iterations),
        Ok(Err(breakdown)) => (None, breakdown.iteration + 1),
        Err(_) => (None, 0),
    }
}

impl Preconditioner<Real> for Cholesky<'_> {
    fn apply(&self, r: &[Real]) -> Vec<Real> {
        self.solution(r)
    }
}

//! A Levenberg-Marquardt step from an earlier factorisation: conjugate
//! gradients on `A x = b` preconditioned by the Cholesky factor of an
//! earlier `A` (Hestenes and Stiefel 1952; Saad, *Iterative Methods for
//! Sparse Linear Systems*, 2003, Algorithm 9.1).
//!
//! Between Levenberg-Marquardt iterations the sparsity pattern of
//! `A = H + λ D` is fixed and its values change little, so the previous
//! factor `M = L Lᵀ ≈ A` makes `M⁻¹ A` close to the identity and a few
//! iterations (one triangular solve pair and one product with `A` each)
//! reach the solution to [`RELATIVE_RESIDUAL`]; that is cheaper than a new
//! numeric factorisation. When it does not converge within the allowed
//! iterations the caller factors `A` afresh.

use crate::math::Real;

use super::sparse_cholesky::{Cholesky, CholeskyPattern};

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
    let dot = |u: &[Real], v: &[Real]| u.iter().zip(v).map(|(a, b)| a * b).sum::<Real>();
    let target = relative.max(RELATIVE_RESIDUAL) * dot(b, b).sqrt();
    let mut x = vec![0.0; b.len()];
    let mut r = b.to_vec();
    let mut z = factor.solution(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    for it in 1..=max_iterations {
        let q = pattern.product(values, &p);
        let curvature = dot(&p, &q);
        if curvature.is_nan() || curvature <= 0.0 || !rz.is_finite() {
            return (None, it);
        }
        let step = rz / curvature;
        for i in 0..x.len() {
            x[i] += step * p[i];
            r[i] -= step * q[i];
        }
        if dot(&r, &r).sqrt() <= target {
            return (Some(x), it);
        }
        z = factor.solution(&r);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..p.len() {
            p[i] = z[i] + beta * p[i];
        }
    }
    (None, max_iterations)
}

//! Preconditioned conjugate gradients for `A x = b`, `A` symmetric positive
//! definite (Hestenes and Stiefel 1952; Saad, *Iterative Methods for Sparse
//! Linear Systems*, 2003, Algorithm 9.1): the one CG loop of the crate.
//!
//! `A` is a closure (a stencil table, a matrix-free product, a sparse
//! pattern's values) and the preconditioner `M ≈ A` a [`Preconditioner`]:
//! [`Jacobi`] (the diagonal), the Cholesky factor of an earlier matrix
//! (fine tuning's Levenberg–Marquardt steps), or a lagged dense Hessian
//! (subdivision solids). The vectors' elements are [`CgElement`]s: scalars,
//! coupled 3-vectors (one system in `3n` unknowns), or points whose three
//! coordinates are three independent systems solved in lockstep (each
//! product with `A` then reads the matrix once for all three; a coordinate
//! stops at its own tolerance and is left alone from then on, so it takes
//! exactly the iterates of a solve of its own).
//!
//! Written by hand rather than taken from faer 0.24, whose CG mishandles a
//! zero initial guess (see DESIGN.md), and because the callers warm-start.

use std::ops::Div;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

/// An element of the vectors CG runs on, and how it splits into lanes:
/// independent systems solved in lockstep.
pub trait CgElement: Copy + PartialEq {
    /// Independent systems: 1, or 3 for a point's coordinates.
    const LANES: usize;
    /// The zero element.
    fn zero() -> Self;
    /// Adds `a`'s and `b`'s share of each lane's inner product to `acc`.
    fn dot_into(a: &Self, b: &Self, acc: &mut [Real; 3]);
    /// `x += α p` and `r −= α q` on the active lanes.
    fn step(x: &mut Self, r: &mut Self, p: &Self, q: &Self, alpha: &[Real; 3], active: &[bool; 3]);
    /// `p = z + β p` on the active lanes.
    fn direction(p: &mut Self, z: &Self, beta: &[Real; 3], active: &[bool; 3]);
    /// Sets lane `k` to zero.
    fn clear(&mut self, k: usize);
    /// `a − b`.
    fn minus(a: &Self, b: &Self) -> Self;
}

impl CgElement for Real {
    const LANES: usize = 1;
    fn zero() -> Self {
        0.0
    }
    fn dot_into(a: &Self, b: &Self, acc: &mut [Real; 3]) {
        acc[0] += a * b;
    }
    fn step(x: &mut Self, r: &mut Self, p: &Self, q: &Self, alpha: &[Real; 3], _: &[bool; 3]) {
        *x += alpha[0] * p;
        *r -= alpha[0] * q;
    }
    fn direction(p: &mut Self, z: &Self, beta: &[Real; 3], _: &[bool; 3]) {
        *p = z + beta[0] * *p;
    }
    fn clear(&mut self, _: usize) {
        *self = 0.0;
    }
    fn minus(a: &Self, b: &Self) -> Self {
        a - b
    }
}

impl CgElement for Vector3 {
    const LANES: usize = 1;
    fn zero() -> Self {
        Vector3::zeros()
    }
    fn dot_into(a: &Self, b: &Self, acc: &mut [Real; 3]) {
        acc[0] += a.dot(b);
    }
    fn step(x: &mut Self, r: &mut Self, p: &Self, q: &Self, alpha: &[Real; 3], _: &[bool; 3]) {
        *x += p * alpha[0];
        *r -= q * alpha[0];
    }
    fn direction(p: &mut Self, z: &Self, beta: &[Real; 3], _: &[bool; 3]) {
        *p = z + *p * beta[0];
    }
    fn clear(&mut self, _: usize) {
        *self = Vector3::zeros();
    }
    fn minus(a: &Self, b: &Self) -> Self {
        a - b
    }
}

impl CgElement for Point3 {
    const LANES: usize = 3;
    fn zero() -> Self {
        Point3::origin()
    }
    fn dot_into(a: &Self, b: &Self, acc: &mut [Real; 3]) {
        for k in 0..3 {
            acc[k] += a[k] * b[k];
        }
    }
    fn step(x: &mut Self, r: &mut Self, p: &Self, q: &Self, alpha: &[Real; 3], active: &[bool; 3]) {
        for k in (0..3).filter(|&k| active[k]) {
            x[k] += alpha[k] * p[k];
            r[k] -= alpha[k] * q[k];
        }
    }
    fn direction(p: &mut Self, z: &Self, beta: &[Real; 3], active: &[bool; 3]) {
        for k in (0..3).filter(|&k| active[k]) {
            p[k] = z[k] + beta[k] * p[k];
        }
    }
    fn clear(&mut self, k: usize) {
        self[k] = 0.0;
    }
    fn minus(a: &Self, b: &Self) -> Self {
        Point3::from(a - b)
    }
}

/// `z = M⁻¹ r` for a preconditioner `M ≈ A`.
pub trait Preconditioner<E> {
    /// The preconditioned residual.
    fn apply(&self, r: &[E]) -> Vec<E>;
}

/// The Jacobi preconditioner: `A`'s diagonal (positive).
pub struct Jacobi<'a>(pub &'a [Real]);

impl<E: CgElement + Div<Real, Output = E>> Preconditioner<E> for Jacobi<'_> {
    fn apply(&self, r: &[E]) -> Vec<E> {
        r.iter().zip(self.0).map(|(r, d)| *r / *d).collect()
    }
}

/// When [`cg`] stops: every lane's `‖b − A x‖ ≤ tolerance · ‖b‖`, or after
/// `max_iterations`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgStop {
    /// Relative residual.
    pub tolerance: Real,
    /// Iterations at most.
    pub max_iterations: usize,
}

/// What [`cg`] did, per lane (lanes beyond [`CgElement::LANES`] are unused).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgOutcome {
    /// Iterations each lane took (`max_iterations` when it did not converge).
    pub iterations: [usize; 3],
    /// Each lane's final relative residual `‖b − A x‖ / ‖b‖`.
    pub relative: [Real; 3],
    /// Every lane reached the tolerance.
    pub converged: bool,
}

impl CgOutcome {
    /// Iterations of the slowest lane.
    pub fn max_iterations(&self) -> usize {
        self.iterations.into_iter().max().unwrap_or(0)
    }

    /// The largest final relative residual.
    pub fn max_relative(&self) -> Real {
        self.relative.into_iter().fold(0.0, Real::max)
    }
}

/// A breakdown of [`cg`]: a residual that is no longer finite, or a
/// direction of non-positive curvature (`A` not positive definite).
#[derive(Clone, Debug, PartialEq)]
pub struct CgBreakdown {
    /// The iteration it happened at.
    pub iteration: usize,
    /// What happened.
    pub what: String,
}

impl From<CgBreakdown> for Error {
    fn from(b: CgBreakdown) -> Error {
        Error::NotConverged(format!(
            "conjugate gradients: {} at iteration {}",
            b.what, b.iteration
        ))
    }
}

/// Each lane's inner product of `a` and `b`.
fn dots<E: CgElement>(a: &[E], b: &[E]) -> [Real; 3] {
    let mut acc = [0.0; 3];
    for (a, b) in a.iter().zip(b) {
        E::dot_into(a, b, &mut acc);
    }
    acc
}

/// Marks the lanes of `active` that the residual `r` has brought within the
/// tolerance after `it` iterations (recording their figures in `out`);
/// false when no lane is left.
fn settled<E: CgElement>(
    r: &[E],
    bnorm: &[Real; 3],
    it: usize,
    tolerance: Real,
    active: &mut [bool; 3],
    out: &mut CgOutcome,
) -> std::result::Result<bool, CgBreakdown> {
    let rr = dots(r, r);
    for k in 0..E::LANES {
        if !active[k] {
            continue;
        }
        let rel = rr[k].sqrt() / bnorm[k];
        if !rel.is_finite() {
            return Err(CgBreakdown {
                iteration: it,
                what: format!("the residual became {rel}"),
            });
        }
        out.relative[k] = rel;
        if rel <= tolerance {
            active[k] = false;
            out.iterations[k] = it;
        }
    }
    Ok(active.iter().any(|&a| a))
}

/// Solves `A x = b` from the initial guess in `x` (overwritten with the
/// solution), `A` applied by `a`, preconditioned by `m`. A lane whose `b` is
/// zero gets `x = 0`; an all-zero `x` starts from `r = b` without a
/// product. An unconverged solve is an outcome and a breakdown the inner
/// error (the caller decides: refactor, or fail); an error of `a` is the
/// outer one.
pub fn cg<E: CgElement>(
    mut a: impl FnMut(&[E]) -> Result<Vec<E>>,
    m: &impl Preconditioner<E>,
    b: &[E],
    x: &mut [E],
    stop: &CgStop,
) -> Result<std::result::Result<CgOutcome, CgBreakdown>> {
    let bnorm = dots(b, b).map(Real::sqrt);
    let mut active = [false; 3];
    let mut out = CgOutcome {
        iterations: [0; 3],
        relative: [0.0; 3],
        converged: true,
    };
    for k in 0..E::LANES {
        if bnorm[k] == 0.0 {
            x.iter_mut().for_each(|e| e.clear(k));
        } else {
            active[k] = true;
        }
    }
    let mut r: Vec<E> = if x.iter().all(|e| *e == E::zero()) {
        b.to_vec()
    } else {
        let ax = a(x)?;
        b.iter().zip(&ax).map(|(b, ax)| E::minus(b, ax)).collect()
    };
    let tol = stop.tolerance;
    match settled(&r, &bnorm, 0, tol, &mut active, &mut out) {
        Err(e) => return Ok(Err(e)),
        Ok(false) => return Ok(Ok(out)),
        Ok(true) => {}
    }
    let mut p = m.apply(&r);
    let mut rz = dots(&r, &p);
    for it in 1..=stop.max_iterations {
        let q = a(&p)?;
        let pq = dots(&p, &q);
        let mut alpha = [0.0; 3];
        for k in (0..E::LANES).filter(|&k| active[k]) {
            if !(pq[k] > 0.0 && pq[k].is_finite()) {
                return Ok(Err(CgBreakdown {
                    iteration: it - 1,
                    what: format!("pᵀAp = {:e}, so the matrix is not positive definite", pq[k]),
                }));
            }
            alpha[k] = rz[k] / pq[k];
        }
        for i in 0..x.len() {
            E::step(&mut x[i], &mut r[i], &p[i], &q[i], &alpha, &active);
        }
        match settled(&r, &bnorm, it, tol, &mut active, &mut out) {
            Err(e) => return Ok(Err(e)),
            Ok(false) => return Ok(Ok(out)),
            Ok(true) => {}
        }
        let z = m.apply(&r);
        let rz_new = dots(&r, &z);
        let mut beta = [0.0; 3];
        for k in (0..E::LANES).filter(|&k| active[k]) {
            beta[k] = rz_new[k] / rz[k];
            rz[k] = rz_new[k];
        }
        for (p, z) in p.iter_mut().zip(&z) {
            E::direction(p, z, &beta, &active);
        }
    }
    for k in (0..E::LANES).filter(|&k| active[k]) {
        out.iterations[k] = stop.max_iterations;
    }
    out.converged = false;
    Ok(Ok(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1-D Laplacian plus `shift` on the diagonal (SPD for `shift > 0`,
    /// indefinite for a negative one), applied to `n` elements.
    fn laplacian<E: CgElement + std::ops::Mul<Real, Output = E>>(
        shift: Real,
    ) -> impl Fn(&[E]) -> Result<Vec<E>> {
        move |x: &[E]| {
            let n = x.len();
            Ok((0..n)
                .map(|i| {
                    let mut acc = x[i] * (2.0 + shift);
                    for j in [i.wrapping_sub(1), i + 1] {
                        if j < n {
                            acc = E::minus(&acc, &x[j]);
                        }
                    }
                    acc
                })
                .collect())
        }
    }

    const STOP: CgStop = CgStop {
        tolerance: 1e-12,
        max_iterations: 200,
    };

    #[test]
    fn solves_a_scalar_system_to_the_tolerance() {
        let n = 40;
        let b: Vec<Real> = (0..n).map(|i| (i as Real * 0.7).sin()).collect();
        let a = laplacian::<Real>(0.1);
        let mut x = vec![0.0; n];
        let out = cg(&a, &Jacobi(&vec![2.1; n]), &b, &mut x, &STOP)
            .unwrap()
            .unwrap();
        assert!(out.converged && out.iterations[0] > 0, "{out:?}");
        let r: Real = a(&x)
            .unwrap()
            .iter()
            .zip(&b)
            .map(|(ax, b)| (ax - b).powi(2))
            .sum::<Real>()
            .sqrt();
        let bn: Real = b.iter().map(|v| v * v).sum::<Real>().sqrt();
        assert!(r <= 1e-12 * bn, "residual {r}");
    }

    /// A point's three coordinates are three systems: each lane takes the
    /// iterates of a scalar solve of its own, bit for bit, stopping at its
    /// own iteration; a zero right-hand side gives a zero lane at once.
    #[test]
    fn lanes_are_independent_solves_in_lockstep() {
        let n = 30;
        let b: Vec<Point3> = (0..n)
            .map(|i| {
                let t = i as Real;
                // Lane 1: an eigenvector of the matrix (one iteration).
                let eigen = (std::f64::consts::PI * (t + 1.0) / (n as Real + 1.0)).sin();
                Point3::new(t.sin(), eigen, 0.0)
            })
            .collect();
        let mut x = vec![Point3::new(0.0, 0.0, 5.0); n];
        let out = cg(
            laplacian::<Point3>(0.05),
            &Jacobi(&vec![2.05; n]),
            &b,
            &mut x,
            &STOP,
        )
        .unwrap()
        .unwrap();
        assert!(out.converged);
        assert_eq!(out.iterations[2], 0);
        assert!(x.iter().all(|p| p.z == 0.0));
        for k in 0..2 {
            let bk: Vec<Real> = b.iter().map(|p| p[k]).collect();
            let mut xk = vec![0.0; n];
            let one = cg(
                laplacian::<Real>(0.05),
                &Jacobi(&vec![2.05; n]),
                &bk,
                &mut xk,
                &STOP,
            )
            .unwrap()
            .unwrap();
            assert_eq!(one.iterations[0], out.iterations[k], "lane {k}");
            assert!(x.iter().zip(&xk).all(|(p, s)| p[k] == *s), "lane {k}");
        }
        assert!(out.iterations[1] <= 2 && out.iterations[0] > 10, "{out:?}");
    }

    #[test]
    fn an_indefinite_matrix_is_a_breakdown_and_a_short_budget_an_outcome() {
        let n = 20;
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let broke = cg(
            laplacian::<Real>(-3.0),
            &Jacobi(&vec![1.0; n]),
            &b,
            &mut x,
            &STOP,
        )
        .unwrap()
        .unwrap_err();
        assert!(broke.what.contains("not positive definite"), "{broke:?}");
        let short = CgStop {
            tolerance: 1e-12,
            max_iterations: 2,
        };
        let mut x = vec![0.0; n];
        let out = cg(
            laplacian::<Real>(0.01),
            &Jacobi(&vec![2.01; n]),
            &b,
            &mut x,
            &short,
        )
        .unwrap()
        .unwrap();
        assert!(!out.converged && out.iterations[0] == 2 && out.relative[0] > 1e-12);
    }
}

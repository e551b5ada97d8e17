//! Preconditioned conjugate gradients for `A x = b` with `A` symmetric
//! positive definite, three right-hand sides (x, y, z) at once.
//!
//! Hestenes and Stiefel 1952; Jacobi (diagonal) preconditioner. Written by
//! hand rather than taken from faer 0.24, whose CG mishandles a zero initial
//! guess (see DESIGN.md), and because fitting warm-starts every solve.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;

/// Options of [`pcg`]. Defaults: relative residual `1e-10`, at most `10 n`
/// iterations (`max_iterations = 0` means that).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgParams {
    /// Stop when `‖b − A x‖ ≤ tolerance · ‖b‖` for every coordinate.
    pub tolerance: Real,
    /// Iteration limit per coordinate (0: ten times the size of the system).
    pub max_iterations: usize,
}

impl Default for PcgParams {
    fn default() -> Self {
        PcgParams {
            tolerance: 1e-10,
            max_iterations: 0,
        }
    }
}

/// What a solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgReport {
    /// Iterations of the slowest coordinate.
    pub iterations: usize,
    /// Largest final relative residual over the coordinates.
    pub relative_residual: Real,
    /// True when every coordinate reached the tolerance.
    pub converged: bool,
    /// Wall time in seconds.
    pub seconds: Real,
}

/// Solves `A x = b` from the initial guess in `x` (overwritten with the
/// solution). Errors on mismatched sizes, a non-positive diagonal, or a
/// non-finite residual; an unconverged solve is reported, not an error.
pub fn pcg(
    a: &StencilTable,
    b: &[Point3],
    x: &mut [Point3],
    params: &PcgParams,
) -> Result<PcgReport> {
    let n = a.num_rows();
    if a.num_cols != n || b.len() != n || x.len() != n {
        return Err(Error::Input(format!(
            "pcg: matrix {}×{}, right-hand side {}, initial guess {}",
            n,
            a.num_cols,
            b.len(),
            x.len()
        )));
    }
    if !(params.tolerance > 0.0 && params.tolerance.is_finite()) {
        return Err(Error::Input(format!(
            "pcg tolerance {} must be positive",
            params.tolerance
        )));
    }
    let start = Instant::now();
    let diag = a.diagonal();
    if let Some(i) = diag.iter().position(|&d| !(d > 0.0 && d.is_finite())) {
        return Err(Error::Input(format!(
            "pcg: diagonal entry {i} is {}; the matrix is not positive definite",
            diag[i]
        )));
    }
    let max_it = if params.max_iterations == 0 {
        10 * n.max(1)
    } else {
        params.max_iterations
    };
    let mut report = PcgReport {
        iterations: 0,
        relative_residual: 0.0,
        converged: true,
        seconds: 0.0,
    };
    for k in 0..3 {
        let bk: Vec<Real> = b.iter().map(|p| p[k]).collect();
        let mut xk: Vec<Real> = x.iter().map(|p| p[k]).collect();
        let (it, rel) = solve_scalar(a, &diag, &bk, &mut xk, params.tolerance, max_it)?;
        for (p, v) in x.iter_mut().zip(&xk) {
            p[k] = *v;
        }
        report.iterations = report.iterations.max(it);
        report.relative_residual = report.relative_residual.max(rel);
        report.converged &= rel <= params.tolerance;
    }
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

fn dot(a: &[Real], b: &[Real]) -> Real {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One coordinate: returns (iterations, relative residual).
fn solve_scalar(
    a: &StencilTable,
    diag: &[Real],
    b: &[Real],
    x: &mut [Real],
    tol: Real,
    max_it: usize,
) -> Result<(usize, Real)> {
    let bnorm = dot(b, b).sqrt();
    if bnorm == 0.0 {
        x.fill(0.0);
        return Ok((0, 0.0));
    }
    let ax = a.apply_scalar(x)?;
    let mut r: Vec<Real> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let mut z: Vec<Real> = r.iter().zip(diag).map(|(r, d)| r / d).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    for it in 0..max_it {
        let rel = dot(&r, &r).sqrt() / bnorm;
        if !rel.is_finite() {
            return Err(Error::NotConverged(format!(
                "pcg residual became {rel} at iteration {it}"
            )));
        }
        if rel <= tol {
            return Ok((it, rel));
        }
        let ap = a.apply_scalar(&p)?;
        let pap = dot(&p, &ap);
        if pap <= 0.0 {
            return Err(Error::NotConverged(format!(
                "pcg: pᵀAp = {pap:e} at iteration {it}; the matrix is not positive definite"
            )));
        }
        let alpha = rz / pap;
        for i in 0..x.len() {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
            z[i] = r[i] / diag[i];
        }
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..p.len() {
            p[i] = z[i] + beta * p[i];
        }
    }
    Ok((max_it, dot(&r, &r).sqrt() / bnorm))
}

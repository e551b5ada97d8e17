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
            "pcg: diagonal entry {i} is {}, so the matrix is not positive definite (an unknown that \
             nothing touches, such as an isolated vertex of the mesh, has no mass or stiffness)",
            diag[i]
        )));
    }
    let max_it = if params.max_iterations == 0 {
        10 * n.max(1)
    } else {
        params.max_iterations
    };
    let (iterations, relative) = solve(a, &diag, b, x, params.tolerance, max_it)?;
    let relative_residual = relative.into_iter().fold(0.0, Real::max);
    Ok(PcgReport {
        iterations: iterations.into_iter().max().unwrap_or(0),
        relative_residual,
        converged: relative.iter().all(|&r| r <= params.tolerance),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// `Σ_i a_i[k] b_i[k]` for each coordinate `k`.
fn dots(a: &[Point3], b: &[Point3]) -> [Real; 3] {
    let mut out = [0.0; 3];
    for (a, b) in a.iter().zip(b) {
        for k in 0..3 {
            out[k] += a[k] * b[k];
        }
    }
    out
}

/// Three independent CG solves, one per coordinate, run in lockstep so that
/// each iteration reads the matrix once for all three (the product is
/// memory-bound). A coordinate stops at its own tolerance and is then left
/// alone, so each takes exactly the iterates of a solve of its own. Returns
/// each coordinate's iterations and relative residual.
fn solve(
    a: &StencilTable,
    diag: &[Real],
    b: &[Point3],
    x: &mut [Point3],
    tol: Real,
    max_it: usize,
) -> Result<([usize; 3], [Real; 3])> {
    let bnorm = dots(b, b).map(Real::sqrt);
    let mut done = [false; 3];
    let mut iterations = [max_it; 3];
    let mut relative = [0.0; 3];
    for k in 0..3 {
        if bnorm[k] == 0.0 {
            x.iter_mut().for_each(|p| p[k] = 0.0);
            (done[k], iterations[k]) = (true, 0);
        }
    }
    let ax = a.apply(x)?;
    let mut r: Vec<Point3> = b
        .iter()
        .zip(&ax)
        .map(|(b, a)| Point3::from(b - a))
        .collect();
    let mut z: Vec<Point3> = r.iter().zip(diag).map(|(r, d)| r / *d).collect();
    let mut p = z.clone();
    let mut rz = dots(&r, &z);
    for it in 0..max_it {
        let rr = dots(&r, &r);
        for k in 0..3 {
            if done[k] {
                continue;
            }
            let rel = rr[k].sqrt() / bnorm[k];
            if !rel.is_finite() {
                return Err(Error::NotConverged(format!(
                    "pcg residual became {rel} at iteration {it}"
                )));
            }
            if rel <= tol {
                (done[k], iterations[k], relative[k]) = (true, it, rel);
            }
        }
        if done.iter().all(|&d| d) {
            return Ok((iterations, relative));
        }
        let ap = a.apply(&p)?;
        let pap = dots(&p, &ap);
        let mut alpha = [0.0; 3];
        for k in (0..3).filter(|&k| !done[k]) {
            if pap[k] <= 0.0 {
                return Err(Error::NotConverged(format!(
                    "pcg: pᵀAp = {:e} at iteration {it}; the matrix is not positive definite",
                    pap[k]
                )));
            }
            alpha[k] = rz[k] / pap[k];
        }
        for i in 0..x.len() {
            for k in (0..3).filter(|&k| !done[k]) {
                x[i][k] += alpha[k] * p[i][k];
                r[i][k] -= alpha[k] * ap[i][k];
                z[i][k] = r[i][k] / diag[i];
            }
        }
        let rz_new = dots(&r, &z);
        let mut beta = [0.0; 3];
        for k in (0..3).filter(|&k| !done[k]) {
            beta[k] = rz_new[k] / rz[k];
            rz[k] = rz_new[k];
        }
        for (p, z) in p.iter_mut().zip(&z) {
            for k in (0..3).filter(|&k| !done[k]) {
                p[k] = z[k] + beta[k] * p[k];
            }
        }
    }
    let rr = dots(&r, &r);
    for k in (0..3).filter(|&k| !done[k]) {
        relative[k] = rr[k].sqrt() / bnorm[k];
    }
    Ok((iterations, relative))
}

//! Conjugate gradients on a [`StencilTable`] `A` (symmetric positive
//! definite), three right-hand sides (x, y, z) at once: the crate's one CG
//! loop ([`crate::linalg::cg`], three lanes in lockstep) with the Jacobi
//! (diagonal) preconditioner, checked inputs and a timed report.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::linalg::{CgStop, Jacobi, cg};
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
        return Err(Error::input(format!(
            "pcg: matrix {}×{}, right-hand side {}, initial guess {}",
            n,
            a.num_cols,
            b.len(),
            x.len()
        )));
    }
    if !(params.tolerance > 0.0 && params.tolerance.is_finite()) {
        return Err(Error::input(format!(
            "pcg tolerance {} must be positive",
            params.tolerance
        )));
    }
    let start = Instant::now();
    let diag = a.diagonal();
    if let Some(i) = diag.iter().position(|&d| !(d > 0.0 && d.is_finite())) {
        return Err(Error::input(format!(
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
    let stop = CgStop {
        tolerance: params.tolerance,
        max_iterations: max_it,
    };
    let outcome = cg(|v| a.apply(v), &Jacobi(&diag), b, x, &stop)??;
    Ok(PcgReport {
        iterations: outcome.max_iterations(),
        relative_residual: outcome.max_relative(),
        converged: outcome.converged,
        seconds: start.elapsed().as_secs_f64(),
    })
}

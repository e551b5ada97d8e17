//! Sparse products of the solid's stencil tables with per-point vectors, and
//! the dense matrices of the (small) control-point system.

use nalgebra::{Cholesky, DMatrix, Dyn};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Real, Vector3, reduction_parts};
use crate::stencil::StencilTable;

/// `out = T x` for a table `T` and per-column vectors `x` (rows in parallel).
pub fn mul_vectors(t: &StencilTable, x: &[Vector3], out: &mut [Vector3]) {
    debug_assert_eq!(x.len(), t.num_cols);
    out.par_iter_mut()
        .with_min_len(512)
        .enumerate()
        .for_each(|(r, o)| {
            let (c, w) = t.row(r);
            let mut s = Vector3::zeros();
            for (&c, &w) in c.iter().zip(w) {
                s += w * x[c as usize];
            }
            *o = s;
        });
}

/// `Tᵀ f` for a table `T` with few columns (`A₁ᵀ f`: forces on mass points
/// to forces on control points), rows split over the workers, each
/// accumulating into its own small buffer.
pub fn mul_transpose_vectors(t: &StencilTable, f: &[Vector3]) -> Vec<Vector3> {
    debug_assert_eq!(f.len(), t.num_rows());
    let n = t.num_cols;
    let rows = t.num_rows();
    let parts = reduction_parts(rows, 1024);
    let size = rows.div_ceil(parts);
    let partial: Vec<Vec<Vector3>> = (0..parts)
        .into_par_iter()
        .map(|p| {
            let mut acc = vec![Vector3::zeros(); n];
            let r0 = p * size;
            for (r, &fr) in f
                .iter()
                .enumerate()
                .take(((p + 1) * size).min(rows))
                .skip(r0)
            {
                let (c, w) = t.row(r);
                for (&c, &w) in c.iter().zip(w) {
                    acc[c as usize] += w * fr;
                }
            }
            acc
        })
        .collect();
    let mut out = vec![Vector3::zeros(); n];
    for acc in partial {
        for (o, a) in out.iter_mut().zip(acc) {
            *o += a;
        }
    }
    out
}

/// A square sparse table as a dense matrix.
pub fn dense(t: &StencilTable) -> DMatrix<Real> {
    let n = t.num_rows();
    let mut m = DMatrix::zeros(n, t.num_cols);
    for r in 0..n {
        let (c, w) = t.row(r);
        for (&c, &w) in c.iter().zip(w) {
            m[(r, c as usize)] += w;
        }
    }
    m
}

/// Cholesky factor of a symmetric positive definite table (`what` names it in the error).
pub fn cholesky(t: &StencilTable, what: &str) -> Result<Cholesky<Real, Dyn>> {
    cholesky_dense(dense(t), what)
}

/// Cholesky factor of a symmetric positive definite matrix (`what` names it in the error).
pub fn cholesky_dense(m: DMatrix<Real>, what: &str) -> Result<Cholesky<Real, Dyn>> {
    let n = m.nrows();
    Cholesky::new(m)
        .ok_or_else(|| Error::Input(format!("the {what} ({n}×{n}) is not positive definite")))
}

/// Solves `P z = r` coordinate by coordinate with a factored scalar `P`.
pub fn solve_vectors(factor: &Cholesky<Real, Dyn>, r: &[Vector3]) -> Vec<Vector3> {
    let n = r.len();
    let mut b = DMatrix::zeros(n, 3);
    for (i, v) in r.iter().enumerate() {
        for k in 0..3 {
            b[(i, k)] = v[k];
        }
    }
    factor.solve_mut(&mut b);
    (0..n)
        .map(|i| Vector3::new(b[(i, 0)], b[(i, 1)], b[(i, 2)]))
        .collect()
}

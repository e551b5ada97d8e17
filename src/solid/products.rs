//! The dense matrices of the solid's (small) control-point system and their
//! Cholesky factors (its sparse products are the stencil tables' own:
//! [`StencilTable::apply_into`], [`StencilTable::apply_transpose_parallel`]).

use nalgebra::{Cholesky, DMatrix, Dyn};

use crate::error::{Error, Result};
use crate::math::{Real, Vector3};
use crate::stencil::StencilTable;

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
        .ok_or_else(|| Error::input(format!("the {what} ({n}×{n}) is not positive definite")))
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

//! Gauss-Legendre quadrature over the limit surface, one rule per polynomial
//! piece.
//!
//! Each level-`L` face of a [`PatchTable`] is a bicubic patch, or near an
//! irregular vertex a quadtree of bicubic leaves (Qin et al. 1998, §4.3 treat
//! these "special elements" by recursive subdivision with area scaling; the
//! leaves are exactly that). An `n × n` Gauss-Legendre rule on every piece is
//! exact for polynomials of degree `2n − 1` per variable, so `n = 4` integrates
//! `JᵀJ` (degree 6) and all stiffness terms exactly in the parameter domain.
//! The innermost cell at an irregular vertex (`4^-(L+6)` of a face) is not a
//! polynomial; the same rule is applied there to the exact surface.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limit::{LimitStencils, PatchTable, SampleStencil};
use crate::math::Real;
use crate::stencil::StencilTable;

/// Quadrature points on the limit surface.
#[derive(Clone, Debug)]
pub struct Quadrature {
    /// Rows of `J, J_u, J_v, J_uu, J_uv, J_vv` at every point, over the
    /// level-`L` vertices of the patch table; derivatives are with respect to
    /// the base faces' `(u, v)` (quad sub-face tiles for n-gons).
    pub rows: LimitStencils,
    /// Weight of every point in the base faces' `du dv`.
    pub weights: Vec<Real>,
    /// Level-`L` patch of every point.
    pub patch: Vec<u32>,
}

/// The `n` Gauss-Legendre nodes and weights on `[0, 1]` (weights sum to 1),
/// by Newton's method on the Legendre polynomial `P_n` (Golub and Welsch
/// give the same nodes as eigenvalues).
pub fn gauss_legendre(n: usize) -> Vec<(Real, Real)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // Initial guess (Tricomi), then Newton on P_n(x) = 0 in [-1, 1].
        let mut x = (std::f64::consts::PI * (i as Real + 0.75) / (n as Real + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as Real;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 0 { 0.0 } else { p0 };
            dp = n as Real * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push(((1.0 - x) / 2.0, w / 2.0));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The tensor rule of the one-dimensional rule `gl` (as
/// [`gauss_legendre`] gives it) on the unit square: points `[a, b]` with
/// weights `w_a w_b`, `a` outer.
pub fn square_rule(gl: &[(Real, Real)]) -> Vec<([Real; 2], Real)> {
    gl.iter()
        .flat_map(|&(a, wa)| gl.iter().map(move |&(b, wb)| ([a, b], wa * wb)))
        .collect()
}

/// `order × order` Gauss-Legendre points on every polynomial piece of every
/// patch of `table`.
pub fn quadrature(table: &PatchTable, order: usize) -> Result<Quadrature> {
    quadrature_on(table, order, true)
}

/// `order × order` Gauss-Legendre points on every patch of `table` as a
/// whole: exact on regular patches like [`quadrature`], approximate on the
/// patches at irregular vertices, which it samples with the same density as
/// the others instead of refining towards the vertex — the sample set for
/// forces (image forces, surface springs), where [`quadrature`]'s deep
/// quadtrees would multiply the work for a vanishing area.
pub fn patch_samples(table: &PatchTable, order: usize) -> Result<Quadrature> {
    quadrature_on(table, order, false)
}

fn quadrature_on(table: &PatchTable, order: usize, per_piece: bool) -> Result<Quadrature> {
    if order == 0 || order > 16 {
        return Err(Error::input(format!(
            "quadrature order {order} must be between 1 and 16"
        )));
    }
    let gl = gauss_legendre(order);
    let per_patch: Vec<Vec<(SampleStencil, Real)>> = (0..table.num_patches())
        .into_par_iter()
        .map(|f| {
            let (_, axes) = table.patch_frame(f);
            let det_axes = (axes[0][0] * axes[1][1] - axes[0][1] * axes[1][0]).abs();
            let inv_axes = invert(axes);
            let mut out = Vec::new();
            let cells = if per_piece {
                table.cells(f)
            } else {
                vec![([[1.0, 0.0], [0.0, 1.0]], [0.0, 0.0])]
            };
            for (jac, off) in cells {
                let inv = invert(jac);
                let det_inv = (inv[0][0] * inv[1][1] - inv[0][1] * inv[1][0]).abs();
                let (sts, ws): (Vec<[Real; 2]>, Vec<Real>) = square_rule(&gl)
                    .into_iter()
                    .map(|([a, b], w)| {
                        let d = [a - off[0], b - off[1]];
                        let st = [
                            inv[0][0] * d[0] + inv[0][1] * d[1],
                            inv[1][0] * d[0] + inv[1][1] * d[1],
                        ];
                        (st, w * det_inv * det_axes)
                    })
                    .unzip();
                for (mut s, w) in table.stencils(f, &sts).into_iter().zip(ws) {
                    rows_to_base(&mut s.weights, inv_axes);
                    out.push((s, w));
                }
            }
            out
        })
        .collect();
    let n_cols = table.to_level().num_rows();
    let total: usize = per_patch.iter().map(Vec::len).sum();
    let mut tables: [StencilTable; 6] =
        std::array::from_fn(|_| StencilTable::with_capacity(n_cols, total, 0));
    let mut weights = Vec::with_capacity(total);
    let mut patch = Vec::with_capacity(total);
    for (f, points) in per_patch.iter().enumerate() {
        for (s, w) in points {
            for (q, t) in tables.iter_mut().enumerate() {
                t.push_row(
                    s.cols
                        .iter()
                        .zip(&s.weights[q])
                        .filter(|(_, x)| **x != 0.0)
                        .map(|(&c, &x)| (c, x)),
                );
            }
            weights.push(*w);
            patch.push(f as u32);
        }
    }
    let [p, du, dv, duu, duv, dvv] = tables;
    Ok(Quadrature {
        rows: LimitStencils {
            p,
            du,
            dv,
            duu,
            duv,
            dvv,
        },
        weights,
        patch,
    })
}

/// Maps derivative rows in `(s, t)` to `(u, v)` for `(s, t) = inv · ((u, v) − o)`:
/// `rows` are `[J, J_s, J_t, J_ss, J_st, J_tt]` over the same columns.
pub(super) fn rows_to_base<W: AsMut<[Real]>>(rows: &mut [W; 6], inv: [[Real; 2]; 2]) {
    for k in 0..rows[0].as_mut().len() {
        let d = crate::limit::chain_rule([1, 2, 3, 4, 5].map(|q| rows[q].as_mut()[k]), inv);
        for (q, x) in d.into_iter().enumerate() {
            rows[q + 1].as_mut()[k] = x;
        }
    }
}

pub(super) fn invert(m: [[Real; 2]; 2]) -> [[Real; 2]; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ]
}

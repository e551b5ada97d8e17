//! The force samples of the dynamics as tangent rows over the control
//! points, built patch by patch.
//!
//! Image and spring forces on the limit surface need, at every sample, the
//! tangents `x_u = J_u p`, `x_v = J_v p` (their cross product is the normal
//! and the area element; Qin et al. 1998, eq. 15 and §5), besides the
//! position `x = J p`, whose rows the springs' own assembly makes
//! ([`PatchAssembly::rows_at`](crate::forces::PatchAssembly::rows_at)), and
//! nothing of second order since `K` and `D` are assembled patch by patch
//! ([`super::patch_stiffness_matrix`]). The same points as
//! [`super::patch_samples`] (an `order × order` Gauss-Legendre rule on every
//! patch), but each row is carried to the control points (`J_u = J_{u,L} S`,
//! `S` the level-`L` refinement) as soon as it is evaluated, so only the two
//! composed tables are ever held — not the level-`L` tables next to their
//! composition, nor every point's dense stencil.

use rayon::prelude::*;

use super::quadrature::{invert, rows_to_base};
use super::{gauss_legendre, square_rule};
use crate::error::{Error, Result};
use crate::limit::PatchTable;
use crate::math::Real;
use crate::stencil::{RowBuilder, StencilTable};

/// Rows `J_u, J_v` of the force samples over the control points.
#[derive(Clone, Debug)]
pub struct SampleRows {
    /// First derivatives in the base faces' `u`.
    pub ju: StencilTable,
    /// First derivatives in `v`.
    pub jv: StencilTable,
    /// Weight of every point in the base faces' `du dv` (sums to the
    /// parameter area).
    pub weights: Vec<Real>,
    /// Level-`L` patch of every point.
    pub patch: Vec<u32>,
}

/// Patches per parallel task.
const PATCHES_PER_TASK: usize = 64;

/// One task's rows: per quantity the row lengths, columns and weights.
type Part = ([(Vec<usize>, Vec<u32>, Vec<Real>); 2], Vec<Real>, Vec<u32>);

/// `order × order` Gauss-Legendre points on every patch of `table` (the
/// points of [`super::patch_samples`]), their tangent rows over the control
/// points.
pub fn patch_sample_rows(table: &PatchTable, order: usize) -> Result<SampleRows> {
    if order == 0 || order > 16 {
        return Err(Error::input(format!(
            "quadrature order {order} must be between 1 and 16"
        )));
    }
    let points = square_rule(&gauss_legendre(order));
    let sts: Vec<[Real; 2]> = points.iter().map(|p| p.0).collect();
    let s = table.to_level();
    let n = table.num_patches();
    let parts: Vec<Part> = (0..n.div_ceil(PATCHES_PER_TASK))
        .into_par_iter()
        .map_init(RowBuilder::default, |b, task| {
            let mut part: Part = Default::default();
            for f in task * PATCHES_PER_TASK..((task + 1) * PATCHES_PER_TASK).min(n) {
                let (_, axes) = table.patch_frame(f);
                let det = (axes[0][0] * axes[1][1] - axes[0][1] * axes[1][0]).abs();
                let inv = invert(axes);
                for (mut st, (_, w)) in table.stencils(f, &sts).into_iter().zip(&points) {
                    rows_to_base(&mut st.weights, inv);
                    for (q, (lens, idx, wts)) in part.0.iter_mut().enumerate() {
                        b.clear();
                        for (&c, &x) in st.cols.iter().zip(&st.weights[q + 1]) {
                            if x != 0.0 {
                                let (ic, iw) = s.row(c as usize);
                                for (&ci, &y) in ic.iter().zip(iw) {
                                    b.add(ci, x * y);
                                }
                            }
                        }
                        let before = idx.len();
                        for (c, x) in b.entries().filter(|e| e.1.abs() > 1e-300) {
                            idx.push(c);
                            wts.push(x);
                        }
                        lens.push(idx.len() - before);
                    }
                    part.1.push(w * det);
                    part.2.push(f as u32);
                }
            }
            part
        })
        .collect();
    let rows = parts.iter().map(|p| p.1.len()).sum();
    let mut weights = Vec::with_capacity(rows);
    let mut patch = Vec::with_capacity(rows);
    let mut tables: [StencilTable; 2] = std::array::from_fn(|q| {
        let entries = parts.iter().map(|p| p.0[q].1.len()).sum();
        StencilTable::with_capacity(s.num_cols, rows, entries)
    });
    // Each part is appended and freed in turn, so the rows are held about
    // once, not twice.
    for (quantities, w, f) in parts {
        for (t, (lens, idx, wts)) in tables.iter_mut().zip(quantities) {
            for l in lens {
                let last = *t.offsets.last().unwrap_or(&0);
                t.offsets.push(last + l);
            }
            t.indices.extend_from_slice(&idx);
            t.weights.extend_from_slice(&wts);
        }
        weights.extend_from_slice(&w);
        patch.extend_from_slice(&f);
    }
    let [ju, jv] = tables;
    Ok(SampleRows {
        ju,
        jv,
        weights,
        patch,
    })
}

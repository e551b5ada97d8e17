//! The implicit step's control-point matrix assembled densely:
//! `P = A₁ᵀ B A₁`, `B = (1 + hγ) M + h² K`, `K` the springs' and ropes'
//! Hessian (McDonnell & Qin's control-point dynamics, eq. 5–6, linearised as
//! in Baraff & Witkin 1998, eq. 6–7; see [`implicit`](super::implicit)).
//!
//! This is exactly the matrix the CG of the implicit step applies
//! matrix-free, so its Cholesky factor, taken at one step's Hessian, solves
//! that step in one CG iteration and preconditions the following steps
//! while the Hessian drifts (the implicit step refreshes it when their CG
//! iterations beyond the first add up to more than
//! [`SolidParams::preconditioner_refresh`](super::SolidParams::preconditioner_refresh)).
//!
//! Assembly, for `N` mass points and `n` free control points:
//! 1. `B` as `3 × 3` blocks on the spring network's block pattern
//!    ([`BlockPattern`], built once per topology): a spring `Δ = Σ b_i x_i`
//!    with Hessian `H` adds `b_i b_j H` to block `(i, j)`;
//! 2. per mass point `i`, the `3 × 3n` row block `Y_i = Σ_j B_ij (A₁[j] ⊗ I₃)`,
//!    then `P += A₁[i]ᵀ ⊗ Y_i` (only the blocks on and right of the
//!    diagonal; `P` is symmetric), the points split over the workers, each
//!    with its own `3n × 3n` accumulator.
//!
//! Cost `O(N · (neighbours · nnz(A₁ row) · 9 + nnz(A₁ row) · 9n))`: about
//! 35 M multiply-adds for the 4,913-point cube, against about 1 M for one
//! matrix-free product, hence the reuse across steps.

use nalgebra::{DMatrix, Matrix3};
use rayon::prelude::*;

use crate::math::{Point3, Real, Vector3, reduction_parts};
use crate::stencil::StencilTable;

use super::springs::{SpringHessians, SpringNetwork};
use super::tools::Rope;

/// Most unknowns (`3 ×` free control points) for which the dense
/// preconditioner is used; larger systems fall back to the spring Laplacian.
pub const MAX_DENSE_UNKNOWNS: usize = 600;

/// Which `3 × 3` blocks of the spring Hessian are non-zero (CSR over mass
/// points, each row sorted), and where every spring adds its blocks.
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockPattern {
    offsets: Vec<usize>,
    cols: Vec<u32>,
    /// Slot of block `(i, i)` of every mass point.
    diag: Vec<usize>,
    /// Slots of `(a, a), (a, b), (b, a), (b, b)` of every edge spring `(a, b)`.
    edge_slots: Vec<[u32; 4]>,
    /// Slots of `(p, q)` for the virtual spring's points `p, q` in order, row-major.
    virtual_slots: Vec<[u32; 9]>,
}

impl BlockPattern {
    /// The pattern of a spring network.
    pub fn new(net: &SpringNetwork) -> BlockPattern {
        let n = net.num_points;
        let mut lists: Vec<Vec<u32>> = (0..n as u32).map(|i| vec![i]).collect();
        for e in &net.edges {
            lists[e[0] as usize].push(e[1]);
            lists[e[1] as usize].push(e[0]);
        }
        for v in &net.virtuals {
            for &a in v {
                for &b in v {
                    if a != b {
                        lists[a as usize].push(b);
                    }
                }
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut cols = Vec::new();
        offsets.push(0);
        for l in &mut lists {
            l.sort_unstable();
            l.dedup();
            cols.extend_from_slice(l);
            offsets.push(cols.len());
        }
        let slot = |i: u32, j: u32| -> u32 {
            let (a, b) = (offsets[i as usize], offsets[i as usize + 1]);
            // Every pair was inserted above, so the search always succeeds.
            (a + cols[a..b].binary_search(&j).unwrap_or(0)) as u32
        };
        let diag = (0..n as u32).map(|i| slot(i, i) as usize).collect();
        let edge_slots = net
            .edges
            .iter()
            .map(|&[a, b]| [slot(a, a), slot(a, b), slot(b, a), slot(b, b)])
            .collect();
        let virtual_slots = net
            .virtuals
            .iter()
            .map(|v| std::array::from_fn(|k| slot(v[k / 3], v[k % 3])))
            .collect();
        BlockPattern {
            offsets,
            cols,
            diag,
            edge_slots,
            virtual_slots,
        }
    }
}

/// A rope's `3 × 3` Hessian at `d`, column by column from its product.
fn rope_matrix(r: &Rope, d: &[Point3]) -> Matrix3<Real> {
    Matrix3::from_columns(&[
        r.hessian_times(d, Vector3::x()),
        r.hessian_times(d, Vector3::y()),
        r.hessian_times(d, Vector3::z()),
    ])
}

/// What the assembly needs besides the pattern and `A₁`.
pub(crate) struct ReducedInputs<'a> {
    /// Their Hessians at the linearisation point.
    pub hess: &'a SpringHessians,
    /// The ropes.
    pub ropes: &'a [Rope],
    /// Mass points (for the ropes' Hessians).
    pub d: &'a [Point3],
    /// Lumped masses.
    pub mass: &'a [Real],
    /// `1 + hγ`.
    pub mass_scale: Real,
    /// `h²`.
    pub h2: Real,
}

/// `B = (1 + hγ) M + h² K` as `3 × 3` blocks on `pattern`.
fn fine_blocks(pattern: &BlockPattern, inp: &ReducedInputs) -> Vec<Matrix3<Real>> {
    let mut blocks = vec![Matrix3::zeros(); pattern.cols.len()];
    for (s, sl) in pattern.edge_slots.iter().enumerate() {
        let h = inp.hess.edge_matrix(s) * inp.h2;
        blocks[sl[0] as usize] += h;
        blocks[sl[1] as usize] -= h;
        blocks[sl[2] as usize] -= h;
        blocks[sl[3] as usize] += h;
    }
    const B: [Real; 3] = [1.0, -0.5, -0.5];
    for (s, sl) in pattern.virtual_slots.iter().enumerate() {
        let h = inp.hess.virtual_matrix(s) * inp.h2;
        for (k, &slot) in sl.iter().enumerate() {
            blocks[slot as usize] += h * (B[k / 3] * B[k % 3]);
        }
    }
    for r in inp.ropes {
        blocks[pattern.diag[r.point]] += rope_matrix(r, inp.d) * inp.h2;
    }
    for (i, &m) in inp.mass.iter().enumerate() {
        blocks[pattern.diag[i]] += Matrix3::identity() * (inp.mass_scale * m);
    }
    blocks
}

/// The dense `3n × 3n` matrix `A₁ᵀ ((1 + hγ) M + h² K) A₁`, unknowns ordered
/// point by point (`x, y, z` of free control point 0, then 1, …).
pub(crate) fn reduced_matrix(
    pattern: &BlockPattern,
    a1: &StencilTable,
    inp: &ReducedInputs,
) -> DMatrix<Real> {
    let blocks = fine_blocks(pattern, inp);
    let n3 = 3 * a1.num_cols;
    let rows = a1.num_rows();
    let parts = reduction_parts(rows, 256);
    let size = rows.div_ceil(parts);
    let partial: Vec<Vec<Real>> = (0..parts)
        .into_par_iter()
        .map(|p| {
            let mut acc = vec![0.0; n3 * n3];
            let mut y = vec![0.0; 3 * n3];
            for i in p * size..((p + 1) * size).min(rows) {
                y.iter_mut().for_each(|v| *v = 0.0);
                let (s0, s1) = (pattern.offsets[i], pattern.offsets[i + 1]);
                for (b, &j) in blocks[s0..s1].iter().zip(&pattern.cols[s0..s1]) {
                    let (cj, wj) = a1.row(j as usize);
                    for (&c, &w) in cj.iter().zip(wj) {
                        let c = 3 * c as usize;
                        for al in 0..3 {
                            let yr = &mut y[al * n3 + c..al * n3 + c + 3];
                            for be in 0..3 {
                                yr[be] += w * b[(al, be)];
                            }
                        }
                    }
                }
                let (ci, wi) = a1.row(i);
                for (&c, &v) in ci.iter().zip(wi) {
                    // P is symmetric: only the blocks right of the diagonal.
                    let c0 = 3 * c as usize;
                    for al in 0..3 {
                        let r = (c0 + al) * n3;
                        let src = &y[al * n3 + c0..(al + 1) * n3];
                        for (o, s) in acc[r + c0..r + n3].iter_mut().zip(src) {
                            *o += v * s;
                        }
                    }
                }
            }
            acc
        })
        .collect();
    let mut sum = vec![0.0; n3 * n3];
    for acc in partial {
        for (o, a) in sum.iter_mut().zip(acc) {
            *o += a;
        }
    }
    // Mirror the upper block triangle (rows of block c hold columns ≥ 3c).
    for r in 0..n3 {
        for col in 3 * (r / 3)..n3 {
            if col / 3 > r / 3 {
                sum[col * n3 + r] = sum[r * n3 + col];
            }
        }
    }
    DMatrix::from_row_slice(n3, n3, &sum)
}

//! Sparse Cholesky factorisation `P A Pᵀ = L Lᵀ` of an implicit step's
//! matrix, for the steps that reuse one matrix (a drag spring held at one
//! surface point, loads that enter the right-hand side only): one
//! factorisation, then two triangular solves per step for the three
//! coordinates at once.
//!
//! `A` is a symmetric positive definite [`StencilTable`] over the control
//! points (scalar entries; x, y and z share it). Its graph is ordered by
//! nested dissection (`linalg::nested_dissection`); the symbolic
//! phase finds the elimination tree and every row's pattern of `L` by
//! `ereach`, the numeric phase is the up-looking algorithm (Davis, *Direct
//! Methods for Sparse Linear Systems*, 2006, §4.1 (etree), §4.2 (`ereach`)
//! and §4.6 (up-looking `L Lᵀ`)). Only the entries of `A` with
//! `P`-order row ≤ column are read, so `A` must be symmetric; a pivot that
//! is not positive (an indefinite or singular matrix) is an error.

use crate::error::{Error, Result};
use crate::linalg::nested_dissection;
use crate::math::{Point3, Real, Vector3};
use crate::stencil::StencilTable;

/// No parent in the elimination tree.
const NONE: usize = usize::MAX;

/// The ordering and the pattern of `L` for one sparsity pattern of `A`.
#[derive(Clone, Debug)]
struct Symbolic {
    /// `perm[k]`: the row of `A` eliminated `k`-th.
    perm: Vec<usize>,
    /// The pattern of `A` this was made for (its `offsets` and `indices`).
    a_offsets: Vec<usize>,
    a_indices: Vec<u32>,
    /// The upper triangle of `C = P A Pᵀ` by columns: row in `C` and slot in
    /// `A`'s weights of every entry.
    c_start: Vec<usize>,
    c_entries: Vec<(u32, usize)>,
    /// Every row of `L` below the diagonal: its columns in an order that
    /// respects the elimination tree (`ereach`).
    r_start: Vec<usize>,
    r_cols: Vec<u32>,
    /// `L` by columns: each column's diagonal first, then its rows in
    /// increasing order.
    l_start: Vec<usize>,
    l_rows: Vec<u32>,
}

impl Symbolic {
    /// Orders `a`'s graph and finds the pattern of its factor.
    fn new(a: &StencilTable) -> Result<Symbolic> {
        let n = a.num_rows();
        if a.num_cols != n {
            return Err(Error::Input(format!(
                "Cholesky: the matrix is {n} × {}, not square",
                a.num_cols
            )));
        }
        let adj: Vec<Vec<usize>> = (0..n)
            .map(|r| {
                let mut v: Vec<usize> = a.indices[a.offsets[r]..a.offsets[r + 1]]
                    .iter()
                    .map(|&c| c as usize)
                    .filter(|&c| c != r)
                    .collect();
                v.sort_unstable();
                v.dedup();
                v
            })
            .collect();
        let (perm, _) = nested_dissection(&adj);
        let mut inv = vec![0usize; n];
        for (k, &r) in perm.iter().enumerate() {
            inv[r] = k;
        }
        // The upper triangle of C by columns (counting sort).
        let mut c_start = vec![0usize; n + 1];
        for r in 0..n {
            for &c in &a.indices[a.offsets[r]..a.offsets[r + 1]] {
                let (i, j) = (inv[r], inv[c as usize]);
                if i <= j {
                    c_start[j + 1] += 1;
                }
            }
        }
        for j in 0..n {
            c_start[j + 1] += c_start[j];
        }
        let mut fill = c_start[..n].to_vec();
        let mut c_entries = vec![(0u32, 0usize); c_start[n]];
        for r in 0..n {
            for slot in a.offsets[r]..a.offsets[r + 1] {
                let (i, j) = (inv[r], inv[a.indices[slot] as usize]);
                if i <= j {
                    c_entries[fill[j]] = (i as u32, slot);
                    fill[j] += 1;
                }
            }
        }
        // Elimination tree (Davis §4.1, with path compression).
        let mut parent = vec![NONE; n];
        let mut ancestor = vec![NONE; n];
        for k in 0..n {
            for &(i, _) in &c_entries[c_start[k]..c_start[k + 1]] {
                let mut i = i as usize;
                while i != NONE && i < k {
                    let next = ancestor[i];
                    ancestor[i] = k;
                    if next == NONE {
                        parent[i] = k;
                    }
                    i = next;
                }
            }
        }
        // Row patterns by `ereach` (Davis §4.2), in topological order.
        let mut mark = vec![NONE; n];
        let mut stack = vec![0u32; n];
        let mut path = Vec::new();
        let mut r_start = Vec::with_capacity(n + 1);
        r_start.push(0);
        let mut r_cols = Vec::new();
        let mut counts = vec![1usize; n];
        for k in 0..n {
            mark[k] = k;
            let mut top = n;
            for &(i, _) in &c_entries[c_start[k]..c_start[k + 1]] {
                let mut i = i as usize;
                while mark[i] != k {
                    path.push(i as u32);
                    mark[i] = k;
                    i = parent[i];
                }
                while let Some(v) = path.pop() {
                    top -= 1;
                    stack[top] = v;
                }
            }
            for &i in &stack[top..] {
                counts[i as usize] += 1;
            }
            r_cols.extend_from_slice(&stack[top..]);
            r_start.push(r_cols.len());
        }
        let mut l_start = vec![0usize; n + 1];
        for j in 0..n {
            l_start[j + 1] = l_start[j] + counts[j];
        }
        let mut l_rows = vec![0u32; l_start[n]];
        let mut next: Vec<usize> = l_start[..n].iter().map(|&s| s + 1).collect();
        for k in 0..n {
            l_rows[l_start[k]] = k as u32;
            for &i in &r_cols[r_start[k]..r_start[k + 1]] {
                l_rows[next[i as usize]] = k as u32;
                next[i as usize] += 1;
            }
        }
        Ok(Symbolic {
            perm,
            a_offsets: a.offsets.clone(),
            a_indices: a.indices.clone(),
            c_start,
            c_entries,
            r_start,
            r_cols,
            l_start,
            l_rows,
        })
    }

    /// True when `a` has the pattern this was made for.
    fn fits(&self, a: &StencilTable) -> bool {
        a.offsets == self.a_offsets && a.indices == self.a_indices
    }

    /// The values of `L` for `a`, which has the pattern this was made for.
    fn numeric(&self, a: &StencilTable) -> Result<Vec<Real>> {
        let n = self.perm.len();
        let mut values = vec![0.0; self.l_rows.len()];
        let mut next: Vec<usize> = self.l_start[..n].iter().map(|&s| s + 1).collect();
        let mut x = vec![0.0; n];
        for k in 0..n {
            for &(i, slot) in &self.c_entries[self.c_start[k]..self.c_start[k + 1]] {
                x[i as usize] += a.weights[slot];
            }
            let mut d = x[k];
            x[k] = 0.0;
            for &i in &self.r_cols[self.r_start[k]..self.r_start[k + 1]] {
                let i = i as usize;
                let lki = x[i] / values[self.l_start[i]];
                x[i] = 0.0;
                for p in self.l_start[i] + 1..next[i] {
                    x[self.l_rows[p] as usize] -= values[p] * lki;
                }
                d -= lki * lki;
                values[next[i]] = lki;
                next[i] += 1;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::Input(format!(
                    "Cholesky: pivot {d:e} at control point {}: the matrix is not positive definite",
                    self.perm[k]
                )));
            }
            values[self.l_start[k]] = d.sqrt();
        }
        Ok(values)
    }
}

/// The factor of one matrix, kept to solve with it again and to factor
/// matrices of the same pattern without ordering them again.
#[derive(Clone, Debug)]
pub struct SparseCholesky {
    symbolic: Symbolic,
    /// The entries of `L`, laid out as `symbolic.l_rows`.
    values: Vec<Real>,
}

impl SparseCholesky {
    /// Orders and factors `a` (symmetric positive definite).
    pub fn new(a: &StencilTable) -> Result<SparseCholesky> {
        let symbolic = Symbolic::new(a)?;
        let values = symbolic.numeric(a)?;
        Ok(SparseCholesky { symbolic, values })
    }

    /// Factors `a` in place of the matrix factored so far; the ordering is
    /// kept when `a` has that matrix's pattern. On an error the previous
    /// factor is kept.
    pub fn refactor(&mut self, a: &StencilTable) -> Result<()> {
        if self.symbolic.fits(a) {
            self.values = self.symbolic.numeric(a)?;
        } else {
            *self = SparseCholesky::new(a)?;
        }
        Ok(())
    }

    /// Entries of `L` (the diagonal included).
    pub fn factor_entries(&self) -> usize {
        self.values.len()
    }

    /// The solution `x` of `A x = b` (three coordinates at once).
    pub fn solve(&self, b: &[Point3]) -> Result<Vec<Point3>> {
        let s = &self.symbolic;
        let n = s.perm.len();
        if b.len() != n {
            return Err(Error::Input(format!(
                "Cholesky: {} right-hand sides for {n} unknowns",
                b.len()
            )));
        }
        let (l, start, rows) = (&self.values, &s.l_start, &s.l_rows);
        let mut y: Vec<Vector3> = s.perm.iter().map(|&r| b[r].coords).collect();
        for j in 0..n {
            y[j] /= l[start[j]];
            let yj = y[j];
            for p in start[j] + 1..start[j + 1] {
                y[rows[p] as usize] -= l[p] * yj;
            }
        }
        for j in (0..n).rev() {
            let mut yj = y[j];
            for p in start[j] + 1..start[j + 1] {
                yj -= l[p] * y[rows[p] as usize];
            }
            y[j] = yj / l[start[j]];
        }
        let mut x = vec![Point3::origin(); n];
        for (k, &r) in s.perm.iter().enumerate() {
            x[r] = Point3::from(y[k]);
        }
        Ok(x)
    }
}

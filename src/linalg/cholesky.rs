//! Sparse Cholesky factorisation `P A Pᵀ = L Lᵀ` with scalar entries, for
//! the implicit steps of the dynamics that reuse one matrix (a drag spring
//! held at one surface point, loads that enter the right-hand side only):
//! one factorisation, then two triangular solves per step for the three
//! coordinates at once.
//!
//! `A` is a symmetric positive definite [`StencilTable`] over the control
//! points (scalar entries; x, y and z share it). Its graph is ordered and
//! the elimination tree and row patterns of `L` found by the shared
//! symbolic phase (`linalg::symbolic`: nested dissection, etree, `ereach`);
//! the numeric phase here is the up-looking algorithm (Davis, *Direct
//! Methods for Sparse Linear Systems*, 2006, §4.6 (up-looking `L Lᵀ`)).
//! Only the entries of `A` with `P`-order row ≤ column are read, so `A`
//! must be symmetric; a pivot that is not positive (an indefinite or
//! singular matrix) is an error.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::stencil::StencilTable;

use super::symbolic::{Ordering, Symbolic};

/// The ordering, the upper triangle of `C = P A Pᵀ` and the pattern of `L`
/// for one sparsity pattern of `A`.
#[derive(Clone, Debug)]
struct Pattern {
    /// `perm[k]`: the row of `A` eliminated `k`-th.
    perm: Vec<usize>,
    /// The pattern of `A` this was made for (its `offsets` and `indices`).
    a_offsets: Vec<usize>,
    a_indices: Vec<u32>,
    /// The upper triangle of `C` by columns: row in `C` and slot in `A`'s
    /// weights of every entry (in the order of `A`'s rows).
    c_start: Vec<usize>,
    c_rows: Vec<usize>,
    c_slots: Vec<usize>,
    /// Elimination tree and row patterns of `L`.
    symbolic: Symbolic,
    /// `L` by columns: each column's diagonal first, then its rows in
    /// increasing order (laid out by `symbolic.l_start`).
    l_rows: Vec<usize>,
}

impl Pattern {
    /// Orders `a`'s graph and finds the pattern of its factor.
    fn new(a: &StencilTable) -> Result<Pattern> {
        let n = a.num_rows();
        if a.num_cols != n {
            return Err(Error::input(format!(
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
        let Ordering { perm, rank, .. } = Ordering::new(&adj);
        // The upper triangle of C by columns (counting sort).
        let mut c_start = vec![0usize; n + 1];
        for r in 0..n {
            for &c in &a.indices[a.offsets[r]..a.offsets[r + 1]] {
                let (i, j) = (rank[r], rank[c as usize]);
                if i <= j {
                    c_start[j + 1] += 1;
                }
            }
        }
        for j in 0..n {
            c_start[j + 1] += c_start[j];
        }
        let mut fill = c_start[..n].to_vec();
        let mut c_rows = vec![0; c_start[n]];
        let mut c_slots = vec![0; c_start[n]];
        for r in 0..n {
            for slot in a.offsets[r]..a.offsets[r + 1] {
                let (i, j) = (rank[r], rank[a.indices[slot] as usize]);
                if i <= j {
                    c_rows[fill[j]] = i;
                    c_slots[fill[j]] = slot;
                    fill[j] += 1;
                }
            }
        }
        let symbolic = Symbolic::new(&c_start, &c_rows);
        let l_rows = symbolic.column_rows();
        Ok(Pattern {
            perm,
            a_offsets: a.offsets.clone(),
            a_indices: a.indices.clone(),
            c_start,
            c_rows,
            c_slots,
            symbolic,
            l_rows,
        })
    }

    /// True when `a` has the pattern this was made for.
    fn fits(&self, a: &StencilTable) -> bool {
        a.offsets == self.a_offsets && a.indices == self.a_indices
    }

    /// The values of `L` for `a`, which has the pattern this was made for:
    /// row `k` of the up-looking algorithm solves `L_{0..k,0..k} x = C_{0..k,k}`
    /// over the row pattern, then `L_kk = √(C_kk − Σ x_i²)`.
    fn numeric(&self, a: &StencilTable) -> Result<Vec<Real>> {
        let n = self.perm.len();
        let l_start = &self.symbolic.l_start;
        let mut values = vec![0.0; self.l_rows.len()];
        let mut next: Vec<usize> = l_start[..n].iter().map(|&s| s + 1).collect();
        let mut x = vec![0.0; n];
        for k in 0..n {
            let column = self.c_start[k]..self.c_start[k + 1];
            for (&i, &slot) in self.c_rows[column.clone()]
                .iter()
                .zip(&self.c_slots[column])
            {
                x[i] += a.weights[slot];
            }
            let mut d = x[k];
            x[k] = 0.0;
            for &i in self.symbolic.row(k) {
                let lki = x[i] / values[l_start[i]];
                x[i] = 0.0;
                for p in l_start[i] + 1..next[i] {
                    x[self.l_rows[p]] -= values[p] * lki;
                }
                d -= lki * lki;
                values[next[i]] = lki;
                next[i] += 1;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::input(format!(
                    "Cholesky: pivot {d:e} at control point {}: the matrix is not positive definite",
                    self.perm[k]
                )));
            }
            values[l_start[k]] = d.sqrt();
        }
        Ok(values)
    }
}

/// The factor of one matrix, kept to solve with it again and to factor
/// matrices of the same pattern without ordering them again.
#[derive(Clone, Debug)]
pub struct SparseCholesky {
    pattern: Pattern,
    /// The entries of `L`, laid out as `pattern.l_rows`.
    values: Vec<Real>,
}

impl SparseCholesky {
    /// Orders and factors `a` (symmetric positive definite).
    pub fn new(a: &StencilTable) -> Result<SparseCholesky> {
        let pattern = Pattern::new(a)?;
        let values = pattern.numeric(a)?;
        Ok(SparseCholesky { pattern, values })
    }

    /// Factors `a` in place of the matrix factored so far; the ordering is
    /// kept when `a` has that matrix's pattern. On an error the previous
    /// factor is kept.
    pub fn refactor(&mut self, a: &StencilTable) -> Result<()> {
        if self.pattern.fits(a) {
            self.values = self.pattern.numeric(a)?;
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
        let s = &self.pattern;
        let n = s.perm.len();
        if b.len() != n {
            return Err(Error::size_mismatch(format!(
                "Cholesky: {} right-hand sides for {n} unknowns",
                b.len()
            )));
        }
        let (l, start, rows) = (&self.values, &s.symbolic.l_start, &s.l_rows);
        let mut y: Vec<Vector3> = s.perm.iter().map(|&r| b[r].coords).collect();
        for j in 0..n {
            y[j] /= l[start[j]];
            let yj = y[j];
            for p in start[j] + 1..start[j + 1] {
                y[rows[p]] -= l[p] * yj;
            }
        }
        for j in (0..n).rev() {
            let mut yj = y[j];
            for p in start[j] + 1..start[j + 1] {
                yj -= l[p] * y[rows[p]];
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

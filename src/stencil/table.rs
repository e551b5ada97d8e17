//! `StencilTable`: a sparse row-major (CSR) matrix of weights over control points.
//!
//! Row `r` says `out[r] = Σ_k weights[k] · in[indices[k]]` for `k` in
//! `offsets[r]..offsets[r + 1]`. Refinement levels, limit evaluation and FFD are
//! all such tables (the model is OpenSubdiv's `Far::StencilTable`).

use rayon::prelude::*;

use super::Primvar;
use super::csr::RowAccumulator;
use crate::error::{Error, Result};
use crate::math::{Real, group_by_key, reduction_parts};

/// A sparse matrix in compressed-row form with `u32` column indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilTable {
    /// Number of columns (control points the rows refer to).
    pub num_cols: usize,
    /// `num_rows + 1` offsets into `indices` / `weights`.
    pub offsets: Vec<usize>,
    /// Column index of each weight.
    pub indices: Vec<u32>,
    /// The weights.
    pub weights: Vec<Real>,
}

/// Most rows per parallel task when applying, composing or building tables.
const CHUNK: usize = 4096;

/// Rows per parallel task for a table of `n` rows: about eight tasks per
/// thread, so that uneven rows (exact evaluations near extraordinary
/// vertices) still share out, and at most [`CHUNK`].
fn chunk_rows(n: usize) -> usize {
    n.div_ceil(8 * rayon::current_num_threads().max(1))
        .clamp(256, CHUNK)
}

impl StencilTable {
    /// The `n × n` identity.
    pub fn identity(n: usize) -> Self {
        StencilTable {
            num_cols: n,
            offsets: (0..=n).collect(),
            indices: (0..n as u32).collect(),
            weights: vec![1.0; n],
        }
    }

    /// The `rows × cols` zero matrix (every row empty).
    pub fn zeros(rows: usize, cols: usize) -> Self {
        StencilTable {
            num_cols: cols,
            offsets: vec![0; rows + 1],
            indices: Vec::new(),
            weights: Vec::new(),
        }
    }

    /// An empty table with `num_cols` columns, ready for [`push_row`](Self::push_row).
    pub fn with_capacity(num_cols: usize, rows: usize, entries: usize) -> Self {
        let mut offsets = Vec::with_capacity(rows + 1);
        offsets.push(0);
        StencilTable {
            num_cols,
            offsets,
            indices: Vec::with_capacity(entries),
            weights: Vec::with_capacity(entries),
        }
    }

    /// Builds a table from rows of `(column, weight)` pairs; repeated columns
    /// within a row are summed.
    pub fn from_rows(num_cols: usize, rows: &[Vec<(u32, Real)>]) -> Self {
        let mut t = Self::with_capacity(num_cols, rows.len(), rows.iter().map(Vec::len).sum());
        for r in rows {
            t.push_row(r.iter().copied());
        }
        t
    }

    /// Appends one row; repeated columns are merged by summing their weights.
    pub fn push_row(&mut self, entries: impl IntoIterator<Item = (u32, Real)>) {
        let start = *self.offsets.last().unwrap_or(&0);
        for (c, w) in entries {
            debug_assert!((c as usize) < self.num_cols);
            if let Some(k) = self.indices[start..].iter().position(|&x| x == c) {
                self.weights[start + k] += w;
            } else {
                self.indices.push(c);
                self.weights.push(w);
            }
        }
        self.offsets.push(self.indices.len());
    }

    /// Number of rows.
    pub fn num_rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of stored weights.
    pub fn num_entries(&self) -> usize {
        self.indices.len()
    }

    /// Columns and weights of row `r`.
    pub fn row(&self, r: usize) -> (&[u32], &[Real]) {
        let (a, b) = (self.offsets[r], self.offsets[r + 1]);
        (&self.indices[a..b], &self.weights[a..b])
    }

    /// Applies the table: `out[r] = Σ w · values[c]` (points, vectors,
    /// scalars: any [`Primvar`]).
    pub fn apply<T: Primvar>(&self, values: &[T]) -> Result<Vec<T>> {
        self.check_input(values.len())?;
        let mut out = vec![T::zero(); self.num_rows()];
        self.apply_into(values, &mut out);
        Ok(out)
    }

    /// Applies the table into a caller-provided buffer of `num_rows` values
    /// (no allocation; rows are processed in parallel).
    ///
    /// Panics if the sizes disagree; [`apply`](Self::apply) checks them first.
    pub fn apply_into<T: Primvar>(&self, values: &[T], out: &mut [T]) {
        assert_eq!(values.len(), self.num_cols);
        assert_eq!(out.len(), self.num_rows());
        let rows = chunk_rows(out.len());
        out.par_chunks_mut(rows)
            .enumerate()
            .for_each(|(ci, chunk)| {
                let r0 = ci * rows;
                for (i, o) in chunk.iter_mut().enumerate() {
                    let (a, b) = (self.offsets[r0 + i], self.offsets[r0 + i + 1]);
                    *o = T::combine(&self.indices[a..b], &self.weights[a..b], values);
                }
            });
    }

    /// Applies the transpose: `out[c] = Σ_r w_rc · values[r]`, the map that
    /// turns forces on samples into forces on control points (`Jᵀ f`); one
    /// pass in row order.
    pub fn apply_transpose<T: Primvar>(&self, values: &[T]) -> Result<Vec<T>> {
        self.check_transpose_input(values.len())?;
        let mut out = vec![T::zero(); self.num_cols];
        for (r, v) in values.iter().enumerate() {
            let (c, w) = self.row(r);
            for (&c, &w) in c.iter().zip(w) {
                out[c as usize].add_scaled(w, v);
            }
        }
        Ok(out)
    }

    /// [`apply_transpose`](Self::apply_transpose) for a table with many
    /// rows and few columns (forces on a solid's mass points to its control
    /// points): the rows are split into parts fixed by their number alone
    /// ([`reduction_parts`]), each summed into its own buffer in parallel,
    /// and the buffers added in order, so the result does not depend on the
    /// thread count.
    ///
    /// Panics unless there is one value per row (as [`apply_into`](Self::apply_into)).
    pub fn apply_transpose_parallel<T: Primvar>(&self, values: &[T]) -> Vec<T> {
        assert_eq!(values.len(), self.num_rows());
        let (n, rows) = (self.num_cols, self.num_rows());
        let parts = reduction_parts(rows, 1024);
        let size = rows.div_ceil(parts);
        let partial: Vec<Vec<T>> = (0..parts)
            .into_par_iter()
            .map(|p| {
                let mut acc = vec![T::zero(); n];
                let r0 = p * size;
                for (r, v) in values
                    .iter()
                    .enumerate()
                    .take(((p + 1) * size).min(rows))
                    .skip(r0)
                {
                    let (c, w) = self.row(r);
                    for (&c, &w) in c.iter().zip(w) {
                        acc[c as usize].add_scaled(w, v);
                    }
                }
                acc
            })
            .collect();
        let mut out = vec![T::zero(); n];
        for acc in partial {
            for (o, a) in out.iter_mut().zip(&acc) {
                o.add_scaled(1.0, a);
            }
        }
        out
    }

    fn check_transpose_input(&self, n: usize) -> Result<()> {
        if n != self.num_rows() {
            return Err(Error::size_mismatch(format!(
                "stencil table has {} rows but {n} values were given",
                self.num_rows()
            )));
        }
        Ok(())
    }

    /// The transposed table (`num_cols × num_rows`).
    pub fn transpose(&self) -> StencilTable {
        let entries = (0..self.num_rows()).flat_map(|r| {
            let (c, w) = self.row(r);
            (c.iter().zip(w)).map(move |(&c, &w)| (c as usize, (r as u32, w)))
        });
        let (offsets, entries) = group_by_key(self.num_cols, entries);
        let (indices, weights) = entries.into_iter().unzip();
        StencilTable {
            num_cols: self.num_rows(),
            offsets,
            indices,
            weights,
        }
    }

    /// The product `self · inner`: rows of `self` expressed over the columns
    /// of `inner`. Composing `S_{n-1} ⋯ S_0` gives `P_n = S P_0`.
    /// Weights smaller than `1e-300` in magnitude after summation are dropped.
    pub fn compose(&self, inner: &StencilTable) -> Result<StencilTable> {
        if self.num_cols != inner.num_rows() {
            return Err(Error::input(format!(
                "cannot compose: outer table has {} columns, inner has {} rows",
                self.num_cols,
                inner.num_rows()
            )));
        }
        let n = self.num_rows();
        let ncols = inner.num_cols;
        // A sparse accumulator per thread.
        let rows = chunk_rows(n);
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> = (0..n.div_ceil(rows))
            .into_par_iter()
            .map_init(
                || RowAccumulator::new(ncols),
                |acc, ci| {
                    let (r0, r1) = (ci * rows, ((ci + 1) * rows).min(n));
                    let mut lens = Vec::with_capacity(r1 - r0);
                    let mut idx = Vec::new();
                    let mut wts = Vec::new();
                    for r in r0..r1 {
                        let (oc, ow) = self.row(r);
                        for (&m, &a) in oc.iter().zip(ow) {
                            let (ic, iw) = inner.row(m as usize);
                            for (&c, &b) in ic.iter().zip(iw) {
                                acc.add(c, a * b);
                            }
                        }
                        lens.push(acc.finish_row(false, |w| w.abs() > 1e-300, &mut idx, &mut wts));
                    }
                    (lens, idx, wts)
                },
            )
            .collect();
        Ok(Self::from_chunks(ncols, n, chunks))
    }

    /// A table made of the given rows of this one, in the given order.
    pub fn select_rows(&self, rows: &[usize]) -> StencilTable {
        let mut t = Self::with_capacity(self.num_cols, rows.len(), 0);
        for &r in rows {
            let (c, w) = self.row(r);
            t.indices.extend_from_slice(c);
            t.weights.extend_from_slice(w);
            t.offsets.push(t.indices.len());
        }
        t
    }

    /// Sum of the weights of each row (1 for an affine-invariant stencil).
    pub fn row_sums(&self) -> Vec<Real> {
        (0..self.num_rows())
            .map(|r| self.row(r).1.iter().sum())
            .collect()
    }

    fn check_input(&self, n: usize) -> Result<()> {
        if n != self.num_cols {
            return Err(Error::input(format!(
                "stencil table expects {} control points, got {n}",
                self.num_cols
            )));
        }
        Ok(())
    }
}

/// Accumulates one stencil row, merging repeated columns.
#[derive(Default, Debug)]
pub struct RowBuilder {
    cols: Vec<u32>,
    wts: Vec<Real>,
    /// `(column, position in cols)` sorted by column, kept only once the row
    /// is longer than [`LINEAR_SEARCH`] (the mask of a vertex of high
    /// valence), so that merging stays O(log n) per entry there.
    sorted: Vec<(u32, u32)>,
}

/// Rows up to this long are searched entry by entry.
const LINEAR_SEARCH: usize = 32;

impl RowBuilder {
    /// Adds `w` to the weight of column `c`.
    #[inline]
    pub fn add(&mut self, c: u32, w: Real) {
        let at = if self.cols.len() <= LINEAR_SEARCH {
            self.cols.iter().position(|&x| x == c)
        } else {
            self.sorted_position(c)
        };
        match at {
            Some(k) => self.wts[k] += w,
            None => {
                self.cols.push(c);
                self.wts.push(w);
            }
        }
    }

    /// The position of column `c` by binary search in `sorted` (made on
    /// first use); a new column is entered at the position it will take.
    fn sorted_position(&mut self, c: u32) -> Option<usize> {
        if self.sorted.len() < self.cols.len() {
            self.sorted = self.cols.iter().zip(0..).map(|(&c, k)| (c, k)).collect();
            self.sorted.sort_unstable();
        }
        match self.sorted.binary_search_by_key(&c, |e| e.0) {
            Ok(k) => Some(self.sorted[k].1 as usize),
            Err(k) => {
                self.sorted.insert(k, (c, self.cols.len() as u32));
                None
            }
        }
    }

    /// Adds every entry of another row scaled by `s`.
    pub fn add_scaled(&mut self, other: &RowBuilder, s: Real) {
        for (&c, &w) in other.cols.iter().zip(&other.wts) {
            self.add(c, s * w);
        }
    }

    /// Removes all entries.
    pub fn clear(&mut self) {
        self.cols.clear();
        self.wts.clear();
        self.sorted.clear();
    }

    /// The entries so far.
    pub fn entries(&self) -> impl Iterator<Item = (u32, Real)> + '_ {
        self.cols.iter().copied().zip(self.wts.iter().copied())
    }
}

impl StencilTable {
    /// Builds `num_rows` rows in parallel; `row(r, b)` fills row `r` into an
    /// empty [`RowBuilder`] `b`.
    pub fn from_row_fn(
        num_rows: usize,
        num_cols: usize,
        row: impl Fn(usize, &mut RowBuilder) + Sync,
    ) -> StencilTable {
        let rows = chunk_rows(num_rows);
        let chunk = |b: &mut RowBuilder, ci: usize| {
            let (r0, r1) = (ci * rows, ((ci + 1) * rows).min(num_rows));
            let mut lens = Vec::with_capacity(r1 - r0);
            let mut idx = Vec::with_capacity(8 * (r1 - r0));
            let mut wts = Vec::with_capacity(8 * (r1 - r0));
            for r in r0..r1 {
                b.clear();
                row(r, b);
                lens.push(b.cols.len());
                idx.extend_from_slice(&b.cols);
                wts.extend_from_slice(&b.wts);
            }
            (lens, idx, wts)
        };
        let nchunks = num_rows.div_ceil(rows);
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> = if nchunks <= 1 {
            let mut b = RowBuilder::default();
            (0..nchunks).map(|ci| chunk(&mut b, ci)).collect()
        } else {
            (0..nchunks)
                .into_par_iter()
                .map_init(RowBuilder::default, chunk)
                .collect()
        };
        Self::from_chunks(num_cols, num_rows, chunks)
    }

    pub(super) fn from_chunks(
        num_cols: usize,
        num_rows: usize,
        chunks: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)>,
    ) -> StencilTable {
        let mut out =
            StencilTable::with_capacity(num_cols, num_rows, chunks.iter().map(|c| c.1.len()).sum());
        for (lens, idx, wts) in chunks {
            for l in lens {
                let last = *out.offsets.last().unwrap_or(&0);
                out.offsets.push(last + l);
            }
            out.indices.extend_from_slice(&idx);
            out.weights.extend_from_slice(&wts);
        }
        out
    }
}

impl StencilTable {
    /// Every row `r` multiplied by `s[r]`.
    pub fn scale_rows(&self, s: &[Real]) -> Result<StencilTable> {
        if s.len() != self.num_rows() {
            return Err(Error::size_mismatch(format!(
                "{} row scales for a table of {} rows",
                s.len(),
                self.num_rows()
            )));
        }
        let mut t = self.clone();
        for (r, &x) in s.iter().enumerate() {
            for w in &mut t.weights[t.offsets[r]..t.offsets[r + 1]] {
                *w *= x;
            }
        }
        Ok(t)
    }

    /// The tables stacked vertically (same number of columns).
    pub fn stack(tables: &[&StencilTable]) -> Result<StencilTable> {
        let cols = tables.first().map_or(0, |t| t.num_cols);
        if let Some(t) = tables.iter().find(|t| t.num_cols != cols) {
            return Err(Error::input(format!(
                "cannot stack tables of {} and {} columns",
                cols, t.num_cols
            )));
        }
        let rows = tables.iter().map(|t| t.num_rows()).sum();
        let entries = tables.iter().map(|t| t.num_entries()).sum();
        let mut out = StencilTable::with_capacity(cols, rows, entries);
        for t in tables {
            for r in 0..t.num_rows() {
                let (c, w) = t.row(r);
                out.indices.extend_from_slice(c);
                out.weights.extend_from_slice(w);
                out.offsets.push(out.indices.len());
            }
        }
        Ok(out)
    }

    /// The Gram matrix `selfᵀ · self` (`num_cols × num_cols`, symmetric):
    /// the assembly of `Σ_r a_rᵀ a_r` over the rows.
    pub fn gram(&self) -> StencilTable {
        self.transpose()
            .compose(self)
            .expect("a table composes with its own transpose")
    }

    /// The diagonal of a square table.
    pub fn diagonal(&self) -> Vec<Real> {
        (0..self.num_rows())
            .map(|r| {
                let (c, w) = self.row(r);
                c.iter()
                    .zip(w)
                    .filter(|(c, _)| **c as usize == r)
                    .map(|(_, w)| w)
                    .sum()
            })
            .collect()
    }

    /// `a · self + b · other` for tables of the same shape.
    pub fn linear_combination(
        &self,
        a: Real,
        other: &StencilTable,
        b: Real,
    ) -> Result<StencilTable> {
        if self.num_cols != other.num_cols || self.num_rows() != other.num_rows() {
            return Err(Error::input(format!(
                "cannot add a {}×{} table to a {}×{} table",
                other.num_rows(),
                other.num_cols,
                self.num_rows(),
                self.num_cols
            )));
        }
        let mut out = StencilTable::with_capacity(
            self.num_cols,
            self.num_rows(),
            self.num_entries().max(other.num_entries()),
        );
        // Where each column sits in the row being built (usize::MAX: not
        // yet), so that merging costs O(1) per entry.
        let mut slot = vec![usize::MAX; self.num_cols];
        for r in 0..self.num_rows() {
            let (c1, w1) = self.row(r);
            let (c2, w2) = other.row(r);
            let terms = c1.iter().zip(w1).map(|(&c, &w)| (c, a * w));
            for (c, w) in terms.chain(c2.iter().zip(w2).map(|(&c, &w)| (c, b * w))) {
                match slot[c as usize] {
                    usize::MAX => {
                        slot[c as usize] = out.indices.len();
                        out.indices.push(c);
                        out.weights.push(w);
                    }
                    k => out.weights[k] += w,
                }
            }
            let start = *out.offsets.last().unwrap_or(&0);
            for &c in &out.indices[start..] {
                slot[c as usize] = usize::MAX;
            }
            out.offsets.push(out.indices.len());
        }
        Ok(out)
    }
}

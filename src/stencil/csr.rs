//! The sparse accumulator of a row-by-row sparse product (Gustavson,
//! "Two fast algorithms for sparse matrices: multiplication and permuted
//! transposition", ACM TOMS 4(3), 1978): dense sums over the columns and a
//! list of the columns touched, so that a row costs only its own fill. The
//! transpose's counting sort is [`crate::math::group_by_key`].

use crate::math::Real;

/// One row's sums at a time, over `n` columns.
pub(super) struct RowAccumulator {
    sums: Vec<Real>,
    seen: Vec<bool>,
    touched: Vec<u32>,
}

impl RowAccumulator {
    /// An empty row over `n` columns.
    pub fn new(n: usize) -> Self {
        RowAccumulator {
            sums: vec![0.0; n],
            seen: vec![false; n],
            touched: Vec::new(),
        }
    }

    /// Adds `w` to column `c`.
    #[inline]
    pub fn add(&mut self, c: u32, w: Real) {
        let cu = c as usize;
        if !self.seen[cu] {
            self.seen[cu] = true;
            self.touched.push(c);
        }
        self.sums[cu] += w;
    }

    /// Appends the row's columns and sums to `indices` and `weights`, in
    /// column order when `sorted` (else in the order they were first
    /// touched), leaving out sums for which `keep` is false; empties the
    /// row. Returns how many entries were appended.
    pub fn finish_row(
        &mut self,
        sorted: bool,
        keep: impl Fn(Real) -> bool,
        indices: &mut Vec<u32>,
        weights: &mut Vec<Real>,
    ) -> usize {
        if sorted {
            self.touched.sort_unstable();
        }
        let before = indices.len();
        for &c in &self.touched {
            let cu = c as usize;
            let w = self.sums[cu];
            if keep(w) {
                indices.push(c);
                weights.push(w);
            }
            self.sums[cu] = 0.0;
            self.seen[cu] = false;
        }
        self.touched.clear();
        indices.len() - before
    }
}

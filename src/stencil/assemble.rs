//! Assembly of dense element matrices into one sparse matrix (the finite
//! element scatter `K = Σ_e P_eᵀ K_e P_e`).

use rayon::prelude::*;

use super::StencilTable;
use super::csr::RowAccumulator;
use crate::error::{Error, Result};
use crate::math::{Real, group_by_key};

/// Dense square matrices, each over a few columns of a larger space, stored
/// one after the other (element `e` is `cols[col_start[e]..col_start[e + 1]]`
/// with its row-major matrix at `entries[entry_start[e]..]`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Elements {
    col_start: Vec<usize>,
    entry_start: Vec<usize>,
    cols: Vec<u32>,
    entries: Vec<Real>,
}

impl Elements {
    /// No elements.
    pub fn new() -> Self {
        Elements {
            col_start: vec![0],
            entry_start: vec![0],
            ..Default::default()
        }
    }

    /// Appends the element `matrix` (row-major, `cols.len()²` entries) over
    /// the global indices `cols`.
    pub fn push(&mut self, cols: &[u32], matrix: &[Real]) -> Result<()> {
        if matrix.len() != cols.len() * cols.len() {
            return Err(Error::input(format!(
                "an element over {} columns has {} entries",
                cols.len(),
                matrix.len()
            )));
        }
        self.cols.extend_from_slice(cols);
        self.entries.extend_from_slice(matrix);
        self.col_start.push(self.cols.len());
        self.entry_start.push(self.entries.len());
        Ok(())
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.col_start.len() - 1
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Columns and row-major matrix of element `e`.
    pub fn get(&self, e: usize) -> (&[u32], &[Real]) {
        (
            &self.cols[self.col_start[e]..self.col_start[e + 1]],
            &self.entries[self.entry_start[e]..self.entry_start[e + 1]],
        )
    }
}

impl StencilTable {
    /// The `n × n` sum of `elements`, each added at its columns (repeated
    /// columns add up). Rows are assembled in parallel, each from the
    /// elements that touch it, so the work is `Σ_e m_e²` for elements of
    /// size `m_e`.
    pub fn from_elements(n: usize, elements: &Elements) -> Result<StencilTable> {
        if let Some(&c) = elements.cols.iter().find(|&&c| c as usize >= n) {
            return Err(Error::input(format!(
                "an element refers to column {c} of a {n}-column matrix"
            )));
        }
        // Which (element, local row) pairs touch each global row.
        let (counts, touching) = group_by_key(
            n,
            (0..elements.len()).flat_map(|e| {
                let (cols, _) = elements.get(e);
                (cols.iter().enumerate()).map(move |(k, &c)| (c as usize, (e as u32, k as u32)))
            }),
        );
        const ROWS: usize = 256;
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> = (0..n.div_ceil(ROWS))
            .into_par_iter()
            .map_init(
                || RowAccumulator::new(n),
                |acc, ci| {
                    let (r0, r1) = (ci * ROWS, ((ci + 1) * ROWS).min(n));
                    let (mut lens, mut idx, mut wts) = (Vec::new(), Vec::new(), Vec::new());
                    for r in r0..r1 {
                        for &(e, k) in &touching[counts[r]..counts[r + 1]] {
                            let (cols, matrix) = elements.get(e as usize);
                            let m = cols.len();
                            let row = &matrix[k as usize * m..(k as usize + 1) * m];
                            for (&c, &w) in cols.iter().zip(row) {
                                acc.add(c, w);
                            }
                        }
                        lens.push(acc.finish_row(true, |_| true, &mut idx, &mut wts));
                    }
                    (lens, idx, wts)
                },
            )
            .collect();
        Ok(Self::from_chunks(n, n, chunks))
    }
}

impl StencilTable {
    /// `Sᵀ A S` for this square `A` (over `s`'s rows): a matrix over the
    /// fine vertices carried to the coarse ones, as `P_L = S P_0` carries
    /// positions the other way.
    pub fn pulled_back(&self, s: &StencilTable) -> Result<StencilTable> {
        s.transpose().compose(&self.compose(s)?)
    }
}

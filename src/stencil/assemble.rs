//! Assembly of dense element matrices into one sparse matrix (the finite
//! element scatter `K = Σ_e P_eᵀ K_e P_e`).

use rayon::prelude::*;

use super::StencilTable;
use crate::error::{Error, Result};
use crate::math::Real;

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
            return Err(Error::Input(format!(
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
            return Err(Error::Input(format!(
                "an element refers to column {c} of a {n}-column matrix"
            )));
        }
        // Which (element, local row) pairs touch each global row.
        let mut counts = vec![0usize; n + 1];
        for &c in &elements.cols {
            counts[c as usize + 1] += 1;
        }
        for r in 0..n {
            counts[r + 1] += counts[r];
        }
        let mut fill = counts.clone();
        let mut touching = vec![(0u32, 0u32); counts[n]];
        for e in 0..elements.len() {
            let (cols, _) = elements.get(e);
            for (k, &c) in cols.iter().enumerate() {
                touching[fill[c as usize]] = (e as u32, k as u32);
                fill[c as usize] += 1;
            }
        }
        const ROWS: usize = 256;
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> = (0..n.div_ceil(ROWS))
            .into_par_iter()
            .map_init(
                || (vec![0.0; n], vec![false; n], Vec::<u32>::new()),
                |(acc, seen, touched), ci| {
                    let (r0, r1) = (ci * ROWS, ((ci + 1) * ROWS).min(n));
                    let (mut lens, mut idx, mut wts) = (Vec::new(), Vec::new(), Vec::new());
                    for r in r0..r1 {
                        for &(e, k) in &touching[counts[r]..counts[r + 1]] {
                            let (cols, matrix) = elements.get(e as usize);
                            let m = cols.len();
                            let row = &matrix[k as usize * m..(k as usize + 1) * m];
                            for (&c, &w) in cols.iter().zip(row) {
                                let cu = c as usize;
                                if !seen[cu] {
                                    seen[cu] = true;
                                    touched.push(c);
                                }
                                acc[cu] += w;
                            }
                        }
                        touched.sort_unstable();
                        let before = idx.len();
                        for &c in touched.iter() {
                            let cu = c as usize;
                            idx.push(c);
                            wts.push(acc[cu]);
                            acc[cu] = 0.0;
                            seen[cu] = false;
                        }
                        touched.clear();
                        lens.push(idx.len() - before);
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

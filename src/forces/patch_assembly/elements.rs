//! The thin plate's and the damping's dense patch elements carried to
//! the control points through a [`PatchAssembly`]'s slots.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limit::PatchTable;
use crate::math::{Real, reduction_parts};

use super::{PatchAssembly, outside, summed};

impl PatchAssembly {
    /// `Σ_f S_fᵀ E_f S_f` in the pattern's order, for each of `N` sets of
    /// elements at once: the dense elements `element(f) = (cols, [E_f, …])`
    /// of every patch `f` over level-`L` vertices of its one-ring (`cols`
    /// sorted, each `E_f` row-major and symmetric, as stiffness, damping
    /// and mass elements are), carried to the control points through
    /// the patch's rows `S_f` of `S` — the finite-element scatter and
    /// `Sᵀ K_L S` in one pass. The patches of a block (a control face's
    /// corners at level 1) are first summed over the union of their columns
    /// (25 level-1 vertices for a regular face against 4 × 16), and the block
    /// is carried once, in fewer products than carrying each patch.
    pub fn values_of_elements<'a, const N: usize>(
        &self,
        table: &PatchTable,
        element: impl Fn(usize) -> (&'a [u32], [&'a [Real]; N]) + Sync,
    ) -> Result<[Vec<Real>; N]> {
        let s = table.to_level();
        let patches = self.ring_offsets.len() - 1;
        // Runs of consecutive patches in one block.
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for f in 0..patches {
            match runs.last_mut() {
                Some(run) if self.block[run.0] == self.block[f] => run.1 = f + 1,
                _ => runs.push((f, f + 1)),
            }
        }
        let chunk = runs.len().div_ceil(reduction_parts(runs.len(), 256)).max(1);
        let parts: Vec<[Vec<Real>; N]> = runs
            .par_chunks(chunk)
            .map(|runs| {
                let mut values: [Vec<Real>; N] =
                    std::array::from_fn(|_| vec![0.0; self.indices.len()]);
                let (mut union, mut at, mut e, mut t, mut c, mut col) = (
                    Vec::new(),
                    Vec::new(),
                    std::array::from_fn::<_, N, _>(|_| Vec::new()),
                    Vec::new(),
                    Vec::new(),
                    Vec::new(),
                );
                for &(lo, hi) in runs {
                    // The union of the run's columns, sorted.
                    union.clear();
                    for f in lo..hi {
                        union.extend_from_slice(element(f).0);
                    }
                    union.sort_unstable();
                    union.dedup();
                    let m = union.len();
                    // `e[k]`: the run's elements summed over the union.
                    for e in &mut e {
                        e.clear();
                        e.resize(m * m, 0.0);
                    }
                    for f in lo..hi {
                        let (cols, es) = element(f);
                        let k = cols.len();
                        if let Some(x) = es.iter().find(|x| x.len() != k * k) {
                            return Err(Error::size_mismatch(format!(
                                "patch {f}'s element has {} entries for {k} columns",
                                x.len()
                            )));
                        }
                        // Present: the union holds every column of the run.
                        at.clear();
                        at.extend(cols.iter().map(|c| union.binary_search(c).unwrap_or(0)));
                        for (sum, x) in e.iter_mut().zip(es) {
                            for (i, &ai) in at.iter().enumerate() {
                                let row = &mut sum[ai * m..(ai + 1) * m];
                                for (&aj, &y) in at.iter().zip(&x[i * k..(i + 1) * k]) {
                                    row[aj] += y;
                                }
                            }
                        }
                    }
                    // Each union column's row of S: its weights and places
                    // in the support (which the run's patches share),
                    // through the one-ring of a patch that has the column.
                    let mut rows: Vec<(&[Real], &[u16])> = vec![(&[], &[]); m];
                    for f in lo..hi {
                        for &col in element(f).0 {
                            let i = union.binary_search(&col).unwrap_or(0);
                            if !rows[i].0.is_empty() {
                                continue;
                            }
                            let at = self.ring_places(f, col).ok_or_else(|| outside(f, col))?;
                            rows[i] = (s.row(col as usize).1, at);
                        }
                    }
                    let b = self.block[lo] as usize;
                    let n = self.support_of_block(b).len();
                    for (e, values) in e.iter().zip(&mut values) {
                        // T = E S (m × n), stored by columns (`t[b m + i]`)
                        // so both products run over contiguous rows; `E` is
                        // symmetric, so its column `j` is its row `j`.
                        t.clear();
                        t.resize(m * n, 0.0);
                        for (j, (w, at)) in rows.iter().enumerate() {
                            let ej = &e[j * m..(j + 1) * m];
                            for (&x, &b) in w.iter().zip(*at) {
                                let b = b as usize;
                                for (o, &y) in t[b * m..(b + 1) * m].iter_mut().zip(ej) {
                                    *o += x * y;
                                }
                            }
                        }
                        // C = Sᵀ T (n × n), from each row `i` of T at once.
                        c.clear();
                        c.resize(n * n, 0.0);
                        for (i, (w, at)) in rows.iter().enumerate() {
                            col.clear();
                            col.extend((0..n).map(|b| t[b * m + i]));
                            for (&x, &a) in w.iter().zip(*at) {
                                let a = a as usize;
                                for (o, &y) in c[a * n..(a + 1) * n].iter_mut().zip(&col) {
                                    *o += x * y;
                                }
                            }
                        }
                        self.scatter(b, &c, values);
                    }
                }
                Ok(values)
            })
            .collect::<Result<_>>()?;
        let mut sums: [Vec<Vec<Real>>; N] = std::array::from_fn(|_| Vec::new());
        for part in parts {
            for (s, v) in sums.iter_mut().zip(part) {
                s.push(v);
            }
        }
        Ok(sums.map(|s| summed(s, self.indices.len())))
    }
}

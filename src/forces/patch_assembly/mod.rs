//! Spring systems assembled straight into a fixed sparsity pattern.
//!
//! A limit-surface point on patch `f` depends only on the control points
//! under `f`'s one-ring, its *support*. So every spring term `k JᵀJ`
//! (Qin, Mandal, Vemuri 1998, eq. 15), and the thin plate `K` and damping
//! `D` assembled patch by patch, are nonzero only on pairs of control
//! points that share a patch support. [`PatchAssembly`] computes that
//! pattern once per control mesh, together with the position of every
//! support pair in it; a spring then costs one dense outer product of its
//! row over the support, in place of composing its stencil with `S` and
//! forming `JᵀJ` by sparse products every step. Consecutive patches with the
//! same support (a regular control face's four corners at level 1) form one
//! *block* that shares its slots, and the springs of a block are summed in a
//! dense buffer that is scattered through the slots once (whole rows: on
//! two cores that measured faster than the upper triangle alone, whose
//! rows of varying length vectorise worse). The thin plate's and damping's dense patch
//! elements are carried to the control points the same way
//! ([`PatchAssembly::values_of_elements`]). The sums are the same as
//! [`spring_system`](super::spring_system)'s and the sparse `Sᵀ K_L S`'s to
//! round-off (`tests/dynamics.rs`).

mod elements;
mod springs;

pub use springs::{PatchRows, RowSprings};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limit::PatchTable;
use crate::math::{Real, group_by_key};
use crate::stencil::StencilTable;

/// Rows of [`PatchAssembly::rows_at`] made by one task.
const ROWS_PER_CHUNK: usize = 2048;

/// The sparsity pattern of the control-point system of a [`PatchTable`] and
/// each patch's support and slots in it.
#[derive(Clone, Debug)]
pub struct PatchAssembly {
    /// Rows (sorted columns) of the pattern over the control points.
    offsets: Vec<usize>,
    indices: Vec<u32>,
    /// Each patch's block: consecutive patches with the same support share
    /// one, and with it their slots.
    block: Vec<u32>,
    /// Control points each block depends on, sorted, block after block.
    support_offsets: Vec<usize>,
    support: Vec<u32>,
    /// The level-`L` vertices of each patch's one-ring, sorted, patch after
    /// patch; for ring vertex `k` (counted over all patches), the columns of
    /// its row of `S` sit at `ring_positions[ring_map[k]..]` in the support.
    ring_offsets: Vec<usize>,
    ring: Vec<u32>,
    ring_map: Vec<usize>,
    ring_positions: Vec<u16>,
    /// For each patch, where the terms of each of its position columns
    /// (`PatchTable::position_columns`) start among its `ring_positions`,
    /// patch after patch (`u16::MAX` for a column outside the ring).
    column_offsets: Vec<usize>,
    column_places: Vec<u16>,
    /// For block `b` with support of size `m`: `m × m` positions in the
    /// pattern, row-major, starting at `slot_offsets[b]`.
    slot_offsets: Vec<usize>,
    slots: Vec<u32>,
}

impl PatchAssembly {
    /// Supports, pattern and slots of `table`'s patches.
    pub fn new(table: &PatchTable) -> Result<Self> {
        let level = table.level();
        let s = table.to_level();
        let n = s.num_cols;
        // Per thread: `seen[c]` is the last patch whose support took control
        // point `c`, `at[c]` its position there.
        let scratch = || (vec![u32::MAX; n], vec![0u32; n]);
        type Ring = (Vec<u32>, Vec<u32>, Vec<u16>, Vec<u16>);
        let rings: Vec<Ring> = (0..table.num_patches())
            .into_par_iter()
            .map_init(scratch, |(seen, at), f| {
                let mut ring = Vec::with_capacity(16);
                for &v in level.face_vertices(f) {
                    for &g in level.vertex_faces(v as usize) {
                        ring.extend_from_slice(level.face_vertices(g as usize));
                    }
                }
                ring.sort_unstable();
                ring.dedup();
                let mut sup: Vec<u32> = Vec::with_capacity(32);
                for &w in &ring {
                    for &c in s.row(w as usize).0 {
                        if seen[c as usize] != f as u32 {
                            seen[c as usize] = f as u32;
                            sup.push(c);
                        }
                    }
                }
                sup.sort_unstable();
                for (i, &c) in sup.iter().enumerate() {
                    at[c as usize] = i as u32;
                }
                // Where each ring vertex's row of S sits in the support
                // (checked below to fit in u16).
                let at: Vec<u16> = ring
                    .iter()
                    .flat_map(|&w| s.row(w as usize).0)
                    .map(|&c| at[c as usize] as u16)
                    .collect();
                // Where each of the patch's position columns starts in `at`
                // (`u16::MAX` for one outside the ring).
                let mut starts = Vec::with_capacity(ring.len());
                let mut start = 0;
                for &w in &ring {
                    starts.push(start);
                    start += s.row(w as usize).0.len();
                }
                let columns: Vec<u16> = table
                    .position_columns(f)
                    .iter()
                    .map(|c| ring.binary_search(c).map_or(u16::MAX, |j| starts[j] as u16))
                    .collect();
                (ring, sup, at, columns)
            })
            .collect();
        let (mut ring_lists, mut supports, mut positions) = (Vec::new(), Vec::new(), Vec::new());
        let mut columns = Vec::with_capacity(rings.len());
        let mut block = Vec::with_capacity(rings.len());
        for (ring, sup, at, cols) in rings {
            if at.len() >= u16::MAX as usize {
                return Err(Error::input(format!(
                    "a patch's one-ring has {} control-point terms, more than 65,534",
                    at.len()
                )));
            }
            columns.push(cols);
            if supports.last() != Some(&sup) {
                supports.push(sup);
            }
            block.push((supports.len() - 1) as u32);
            ring_lists.push(ring);
            positions.push(at);
        }
        let rings = ring_lists;
        if let Some(big) = supports.iter().find(|sup| sup.len() > u16::MAX as usize) {
            return Err(Error::input(format!(
                "a patch depends on {} control points, more than 65,535",
                big.len()
            )));
        }
        let support_offsets = offsets_of(supports.iter().map(Vec::len));
        let ring_offsets = offsets_of(rings.iter().map(Vec::len));
        let column_offsets = offsets_of(columns.iter().map(Vec::len));
        let column_places = par_concat(columns);
        let ring_positions: Vec<u16> = par_concat(positions);
        let ring: Vec<u32> = par_concat(rings);
        let ring_map = offsets_of(ring.iter().map(|&w| s.row(w as usize).0.len()));
        let support: Vec<u32> = supports.concat();
        // The patches over each control point, then each row's columns.
        let (count, patches_of) = group_by_key(
            n,
            (support_offsets.windows(2).enumerate()).flat_map(|(f, w)| {
                support[w[0]..w[1]]
                    .iter()
                    .map(move |&c| (c as usize, f as u32))
            }),
        );
        let rows: Vec<Vec<u32>> = (0..n)
            .into_par_iter()
            .map_init(
                || vec![u32::MAX; n],
                |seen, c| {
                    let mut row: Vec<u32> = Vec::with_capacity(64);
                    for &f in &patches_of[count[c]..count[c + 1]] {
                        for &b in &supports[f as usize] {
                            if seen[b as usize] != c as u32 {
                                seen[b as usize] = c as u32;
                                row.push(b);
                            }
                        }
                    }
                    row.sort_unstable();
                    row
                },
            )
            .collect();
        let offsets = offsets_of(rows.iter().map(Vec::len));
        let indices = par_concat(rows);
        let per_block: Vec<Vec<u32>> = supports
            .par_iter()
            .map(|sup| {
                let mut out = Vec::with_capacity(sup.len() * sup.len());
                for &a in sup {
                    let (lo, hi) = (offsets[a as usize], offsets[a as usize + 1]);
                    let row = &indices[lo..hi];
                    // Both sorted: one merge. Every `b` is present by
                    // construction (it shares this patch with `a`).
                    let mut k = 0;
                    for b in sup {
                        while k + 1 < row.len() && row[k] < *b {
                            k += 1;
                        }
                        out.push((lo + k) as u32);
                    }
                }
                out
            })
            .collect();
        let slot_offsets = offsets_of(per_block.iter().map(Vec::len));
        if indices.len() > u32::MAX as usize {
            return Err(Error::input(format!(
                "the control-point system would have {} entries, more than 2³² − 1",
                indices.len()
            )));
        }
        Ok(PatchAssembly {
            offsets,
            indices,
            block,
            support_offsets,
            support,
            ring_offsets,
            ring,
            ring_map,
            ring_positions,
            column_offsets,
            column_places,
            slot_offsets,
            slots: par_concat(per_block),
        })
    }

    /// Number of stored entries of the pattern.
    pub fn num_entries(&self) -> usize {
        self.indices.len()
    }

    /// The values of `m` (whose nonzeros must lie in the pattern, as those
    /// of matrices assembled patch by patch over the same table do) in the
    /// pattern's order.
    pub fn values_of(&self, m: &StencilTable) -> Result<Vec<Real>> {
        let n = self.offsets.len() - 1;
        if m.num_rows() != n || m.num_cols != n {
            return Err(Error::size_mismatch(format!(
                "a {}×{} matrix for a system of {n} control points",
                m.num_rows(),
                m.num_cols
            )));
        }
        let mut values = vec![0.0; self.indices.len()];
        for r in 0..n {
            let (lo, hi) = (self.offsets[r], self.offsets[r + 1]);
            let row = &self.indices[lo..hi];
            let (cols, ws) = m.row(r);
            for (c, &w) in cols.iter().zip(ws) {
                match row.binary_search(c) {
                    Ok(k) => values[lo + k] += w,
                    Err(_) if w == 0.0 => {}
                    Err(_) => {
                        return Err(Error::input(format!(
                            "matrix entry ({r}, {c}) = {w} lies outside the patches' supports"
                        )));
                    }
                }
            }
        }
        Ok(values)
    }

    /// The matrix with `values` in the pattern.
    pub fn matrix(&self, values: Vec<Real>) -> StencilTable {
        debug_assert_eq!(values.len(), self.indices.len());
        StencilTable {
            num_cols: self.offsets.len() - 1,
            offsets: self.offsets.clone(),
            indices: self.indices.clone(),
            weights: values,
        }
    }

    /// Where the columns of level vertex `c`'s row of `S` sit in patch
    /// `f`'s support (from that place on, in the row's order); `None` when
    /// `c` is not in `f`'s one-ring.
    fn ring_places(&self, f: usize, c: u32) -> Option<&[u16]> {
        let first = self.ring_offsets[f];
        let ring = &self.ring[first..self.ring_offsets[f + 1]];
        let j = ring.binary_search(&c).ok()?;
        Some(&self.ring_positions[self.ring_map[first + j]..])
    }

    fn support_of_block(&self, b: usize) -> &[u32] {
        &self.support[self.support_offsets[b]..self.support_offsets[b + 1]]
    }

    /// Adds block `b`'s dense `m × m` sum `c` (row-major over its support) to
    /// `values` through its slots.
    fn scatter(&self, b: usize, c: &[Real], values: &mut [Real]) {
        let slots = &self.slots[self.slot_offsets[b]..self.slot_offsets[b + 1]];
        for (&slot, &x) in slots.iter().zip(c) {
            values[slot as usize] += x;
        }
    }

    /// [`scatter`](Self::scatter) of a symmetric sum of which only the
    /// upper triangle of `c` was summed: the lower is copied from it first.
    fn scatter_upper(&self, b: usize, c: &mut [Real], values: &mut [Real]) {
        let m = self.support_of_block(b).len();
        for a in 1..m {
            for e in 0..a {
                c[a * m + e] = c[e * m + a];
            }
        }
        self.scatter(b, c, values);
    }
}

/// The error for level vertex `c` outside patch `f`'s one-ring.
fn outside(f: usize, c: u32) -> Error {
    Error::Topology(format!("level vertex {c} is outside patch {f}'s one-ring"))
}

/// The entrywise sum of `parts` (zeros of length `len` if there are none).
fn summed(parts: Vec<Vec<Real>>, len: usize) -> Vec<Real> {
    let mut parts = parts.into_iter();
    let mut out = parts.next().unwrap_or_else(|| vec![0.0; len]);
    for p in parts {
        for (a, b) in out.iter_mut().zip(p) {
            *a += b;
        }
    }
    out
}

/// `parts.concat()`, with the copies and the parts' frees spread over the
/// thread pool: a serial concatenation of large parts faults the whole
/// result in, and frees every part, on the caller's thread.
fn par_concat<T: Copy + Default + Send + Sync>(parts: Vec<Vec<T>>) -> Vec<T> {
    let mut out = vec![T::default(); parts.iter().map(Vec::len).sum()];
    let mut rest = out.as_mut_slice();
    let mut pieces = Vec::with_capacity(parts.len());
    for part in parts {
        let (head, tail) = rest.split_at_mut(part.len());
        pieces.push((head, part));
        rest = tail;
    }
    pieces
        .into_par_iter()
        .for_each(|(to, from)| to.copy_from_slice(&from));
    out
}

/// Running offsets `[0, l₀, l₀ + l₁, …]` of consecutive blocks of lengths `l`.
fn offsets_of(lengths: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut out = vec![0];
    for l in lengths {
        out.push(out.last().copied().unwrap_or(0) + l);
    }
    out
}

fn check_lengths(a: usize, b: usize, c: usize) -> Result<()> {
    if a == b && b == c {
        Ok(())
    } else {
        Err(Error::size_mismatch(format!(
            "springs: mismatched lengths {a}, {b} and {c}"
        )))
    }
}

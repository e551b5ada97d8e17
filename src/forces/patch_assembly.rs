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

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limit::{ClosestPoint, PatchTable};
use crate::math::{Point3, Real, group_by_key, reduction_parts};
use crate::stencil::StencilTable;

use super::SpringSystem;

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
                return Err(Error::Input(format!(
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
            return Err(Error::Input(format!(
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
            return Err(Error::Input(format!(
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
            return Err(Error::Input(format!(
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
                        return Err(Error::Input(format!(
                            "matrix entry ({r}, {c}) = {w} lies outside the patches' supports"
                        )));
                    }
                }
            }
        }
        Ok(values)
    }

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
                            return Err(Error::Input(format!(
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

    /// Springs from `points[i]` to their closest points `closest[i]` with
    /// stiffness `k[i]`: the same system as
    /// [`spring_system`](super::spring_system), its matrix in the pattern;
    /// with `and`, plus those springs ([`row_springs`](Self::row_springs)),
    /// summed in the same pass (a block's springs of both kinds share one
    /// dense sum and one scatter).
    pub fn data_springs(
        &self,
        table: &PatchTable,
        points: &[Point3],
        closest: &[ClosestPoint],
        k: &[Real],
        and: Option<RowSprings>,
    ) -> Result<SpringSystem> {
        check_lengths(points.len(), closest.len(), k.len())?;
        let n = points.len();
        let extra = match and {
            Some(r) => r.check()?,
            None => 0,
        };
        self.springs(
            n + extra,
            |i| match and {
                Some(r) if i >= n => r.rows.patch[i - n] as usize,
                _ => closest[i].patch.0 as usize,
            },
            |i, f, u| match and {
                Some(r) if i >= n => Ok(r.spring(i - n, u)),
                _ => {
                    self.add_position_row(table, f, closest[i].patch.1, u)?;
                    Ok((closest[i].point, points[i], k[i]))
                }
            },
        )
    }

    /// Adds the row over the control points of the limit point at `st` of
    /// patch `f` to `u` (zeroed, over `f`'s support): the patch's weights
    /// over its level-`L` one-ring carried through their rows of `S`.
    fn add_position_row(
        &self,
        table: &PatchTable,
        f: usize,
        st: [Real; 2],
        u: &mut [Real],
    ) -> Result<()> {
        let s = table.to_level();
        let mut missing = None;
        let places = &self.column_places[self.column_offsets[f]..self.column_offsets[f + 1]];
        // The patch's places start where its first ring vertex's do.
        let base = self.ring_map[self.ring_offsets[f]];
        table.visit_position_terms(f, st, |k, c, wc| {
            let at = match k.map(|k| places[k]) {
                Some(p) if p != u16::MAX => Some(&self.ring_positions[base + p as usize..]),
                _ => self.ring_places(f, c),
            };
            match at {
                Some(at) => {
                    for (&x, &a) in s.row(c as usize).1.iter().zip(at) {
                        u[a as usize] += wc * x;
                    }
                }
                None => missing = Some(c),
            }
        });
        match missing {
            Some(c) => Err(outside(f, c)),
            None => Ok(()),
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

    /// The rows over the control points of the limit points `at[i] = (f,
    /// st)` (patch `f` of `table`, its `(s, t)`), each entry's place in its
    /// patch's support kept: for springs that stay on their patches step
    /// after step ([`row_springs`](Self::row_springs)). Errors when a patch
    /// is out of range.
    pub fn rows_at(&self, table: &PatchTable, at: &[(usize, [Real; 2])]) -> Result<PatchRows> {
        let patches = self.block.len();
        if table.num_patches() != patches {
            return Err(Error::Input(format!(
                "a table of {} patches for an assembly of {patches}",
                table.num_patches()
            )));
        }
        // Chunks of rows made in parallel, each as its rows' lengths and
        // entries (control point, weight, place in the support).
        type Chunk = (Vec<usize>, Vec<u32>, Vec<Real>, Vec<u16>);
        let chunks: Vec<Chunk> = at
            .par_chunks(ROWS_PER_CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let (mut u, mut out) = (Vec::new(), Chunk::default());
                for (i, &(f, st)) in chunk.iter().enumerate() {
                    if f >= patches {
                        return Err(Error::Input(format!(
                            "row {} is on patch {f} of {patches}",
                            c * ROWS_PER_CHUNK + i
                        )));
                    }
                    let sup = self.support_of_block(self.block[f] as usize);
                    u.clear();
                    u.resize(sup.len(), 0.0);
                    self.add_position_row(table, f, st, &mut u)?;
                    let before = out.1.len();
                    for (a, &w) in u.iter().enumerate().filter(|e| *e.1 != 0.0) {
                        out.1.push(sup[a]);
                        out.2.push(w);
                        out.3.push(a as u16);
                    }
                    out.0.push(out.1.len() - before);
                }
                Ok(out)
            })
            .collect::<Result<_>>()?;
        let (mut lengths, mut indices, mut weights, mut places) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (l, i, w, p) in chunks {
            lengths.push(l);
            indices.push(i);
            weights.push(w);
            places.push(p);
        }
        let rows = StencilTable {
            num_cols: self.offsets.len() - 1,
            offsets: offsets_of(lengths.into_iter().flatten()),
            indices: par_concat(indices),
            weights: par_concat(weights),
        };
        let places = par_concat(places);
        Ok(PatchRows {
            rows,
            patch: at.iter().map(|a| a.0 as u32).collect(),
            at: places,
        })
    }

    /// Springs from surface points `x[i] = rows[i] · p` to targets `d[i]`
    /// with stiffness `k[i]`: the system of
    /// [`row_springs`](super::row_springs), its matrix in the pattern.
    pub fn row_springs(
        &self,
        rows: &PatchRows,
        x: &[Point3],
        d: &[Point3],
        k: &[Real],
    ) -> Result<SpringSystem> {
        let r = RowSprings { rows, x, d, k };
        self.springs(
            r.check()?,
            |i| rows.patch[i] as usize,
            |i, _, u| Ok(r.spring(i, u)),
        )
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

    /// Sums `k uuᵀ`, `k u d` and `½ k |x − d|²` over `count` springs on
    /// patches `patch_of(i)`; `spring(i, f, u)` writes spring `i`'s row over
    /// its patch `f`'s support into the zeroed `u` and returns `x`, `d` and
    /// `k`. The springs are taken block by block, each block's `k uuᵀ`
    /// summed in a dense buffer and scattered once.
    fn springs(
        &self,
        count: usize,
        patch_of: impl Fn(usize) -> usize + Sync,
        spring: impl Fn(usize, usize, &mut [Real]) -> Result<(Point3, Point3, Real)> + Sync,
    ) -> Result<SpringSystem> {
        let n = self.offsets.len() - 1;
        let patches = self.block.len();
        let mut order: Vec<(u32, usize)> = Vec::with_capacity(count);
        for i in 0..count {
            let f = patch_of(i);
            if f >= patches {
                return Err(Error::Input(format!(
                    "spring {i} is on patch {f} of {patches}"
                )));
            }
            order.push((self.block[f], i));
        }
        order.par_sort_unstable();
        let chunk = count.div_ceil(reduction_parts(count, 4096)).max(1);
        let parts: Vec<(Vec<Real>, Vec<Point3>, Real)> = order
            .par_chunks(chunk)
            .map(|ids| {
                let mut values = vec![0.0; self.indices.len()];
                let mut rhs = vec![Point3::origin(); n];
                let mut energy = 0.0;
                let (mut u, mut c, mut block) = (Vec::new(), Vec::new(), None);
                for &(b, i) in ids {
                    let b = b as usize;
                    let sup = self.support_of_block(b);
                    let m = sup.len();
                    if block != Some(b) {
                        if let Some(done) = block {
                            self.scatter_upper(done, &mut c, &mut values);
                        }
                        block = Some(b);
                        c.clear();
                        c.resize(m * m, 0.0);
                    }
                    u.clear();
                    u.resize(m, 0.0);
                    let (x, d, k) = spring(i, patch_of(i), &mut u)?;
                    if k == 0.0 {
                        continue;
                    }
                    if !(k > 0.0 && k.is_finite()) {
                        return Err(Error::Input(format!("spring {i} has stiffness {k}")));
                    }
                    energy += 0.5 * k * (x - d).norm_squared();
                    for a in 0..m {
                        let ka = k * u[a];
                        if ka == 0.0 {
                            continue;
                        }
                        rhs[sup[a] as usize].coords += ka * d.coords;
                        // The upper triangle only; mirrored before the scatter.
                        for (o, &y) in c[a * m + a..(a + 1) * m].iter_mut().zip(&u[a..]) {
                            *o += ka * y;
                        }
                    }
                }
                if let Some(done) = block {
                    self.scatter_upper(done, &mut c, &mut values);
                }
                Ok((values, rhs, energy))
            })
            .collect::<Result<_>>()?;
        let mut rhs = vec![Point3::origin(); n];
        let mut energy = 0.0;
        let mut values = Vec::with_capacity(parts.len());
        for (v, r, e) in parts {
            values.push(v);
            for (a, b) in rhs.iter_mut().zip(r) {
                a.coords += b.coords;
            }
            energy += e;
        }
        let values = summed(values, self.indices.len());
        Ok(SpringSystem {
            matrix: self.matrix(values),
            rhs,
            energy,
        })
    }
}

/// Rows over the control points on known patches of a [`PatchAssembly`]
/// ([`PatchAssembly::rows_at`]).
#[derive(Clone, Debug)]
pub struct PatchRows {
    rows: StencilTable,
    /// Each row's patch.
    patch: Vec<u32>,
    /// Each entry's place in its row's patch support.
    at: Vec<u16>,
}

impl PatchRows {
    /// The rows.
    pub fn rows(&self) -> &StencilTable {
        &self.rows
    }
}

/// Springs from surface points `x[i] = rows[i] · p` to targets `d[i]` with
/// stiffness `k[i]` ([`PatchAssembly::row_springs`]).
#[derive(Clone, Copy, Debug)]
pub struct RowSprings<'a> {
    /// Where the springs attach.
    pub rows: &'a PatchRows,
    /// The attachments' current positions.
    pub x: &'a [Point3],
    /// The targets.
    pub d: &'a [Point3],
    /// The stiffnesses.
    pub k: &'a [Real],
}

impl RowSprings<'_> {
    /// The number of springs, or an error when the lengths differ.
    fn check(&self) -> Result<usize> {
        let n = self.rows.rows.num_rows();
        check_lengths(n, self.x.len(), self.d.len())?;
        check_lengths(n, self.k.len(), self.d.len())?;
        Ok(n)
    }

    /// Writes spring `i`'s row over its patch's support into `u`; its `x`,
    /// `d` and `k`.
    fn spring(&self, i: usize, u: &mut [Real]) -> (Point3, Point3, Real) {
        let r = &self.rows.rows;
        let (lo, hi) = (r.offsets[i], r.offsets[i + 1]);
        for (&a, &w) in self.rows.at[lo..hi].iter().zip(&r.weights[lo..hi]) {
            u[a as usize] += w;
        }
        (self.x[i], self.d[i], self.k[i])
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
        Err(Error::Input(format!(
            "springs: mismatched lengths {a}, {b} and {c}"
        )))
    }
}

//! Springs assembled through a [`PatchAssembly`]: data springs at closest
//! points, and springs on rows of the limit surface at fixed parameters
//! ([`PatchRows`]).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limit::{ClosestPoint, PatchTable};
use crate::math::{Point3, Real, reduction_parts};
use crate::stencil::StencilTable;

use super::{
    PatchAssembly, ROWS_PER_CHUNK, check_lengths, offsets_of, outside, par_concat, summed,
};
use crate::forces::SpringSystem;

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

impl PatchAssembly {
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

    /// The rows over the control points of the limit points `at[i] = (f,
    /// st)` (patch `f` of `table`, its `(s, t)`), each entry's place in its
    /// patch's support kept: for springs that stay on their patches step
    /// after step ([`row_springs`](Self::row_springs)). Errors when a patch
    /// is out of range.
    pub fn rows_at(&self, table: &PatchTable, at: &[(usize, [Real; 2])]) -> Result<PatchRows> {
        let patches = self.block.len();
        if table.num_patches() != patches {
            return Err(Error::size_mismatch(format!(
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
                        return Err(Error::input(format!(
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
                return Err(Error::input(format!(
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
                        return Err(Error::input(format!("spring {i} has stiffness {k}")));
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

//! A small sparse Cholesky factorisation `P A Pᵀ = L Lᵀ` for the
//! Gauss-Newton systems of fine tuning (symmetric positive definite, a few
//! thousand unknowns, the same pattern at every step), in 3 × 3 blocks.
//!
//! Up-looking algorithm (Davis, *Direct Methods for Sparse Linear Systems*,
//! 2006, §4.6) on the graph of nodes (a point's unknowns); the ordering
//! (nested dissection, minimum degree on small parts), elimination tree and
//! row patterns (`ereach`, §4.1–4.2) come from the symbolic phase shared
//! with the scalar factor (`linalg::symbolic`). On the benchmark
//! torus (1,900 nodes) building the pattern took 20–37 ms with nested
//! dissection against 85–177 ms with minimum degree on the whole graph (a
//! loaded 2-core machine), with 105,041 factor blocks against 116,058.
//! Every node is a block of 3 unknowns (nodes with fewer get
//! unit-diagonal padding, nodes with more are split), so the inner loops are
//! 3 × 3 matrix products: `Z_i = L_ii⁻¹ X_i`, `X_r −= L_ri Z_i`,
//! `D −= Z_iᵀ Z_i`, `L_ki = Z_iᵀ`, `L_kk = chol(D)`. Written here rather than
//! taking faer's: on the benchmark torus system (5,700 unknowns) faer 0.24's
//! sparse `Llt` (its own ordering, sequential) took 7 ms symbolic, 20 ms
//! numeric and 1.5 ms per solve, against 13–15, 34 and 1.1 ms for this
//! code, serial, in the same hour: not enough to add the dependency.
//!
//! Two threads: nested dissection's first separator splits the graph into
//! parts A and B that share no row of `L`. Their rows are eliminated in
//! parallel; each separator row then takes its entries in A's and in B's
//! columns in parallel (each with its own accumulator for the separator
//! rows), and its separator entries serially. The triangular solves split
//! the same way. On the benchmark torus (58 % of the factor's work is in
//! the 100 rows of the first separator) a factorisation took 27–34 ms
//! against 37–58 ms serially (6 interleaved runs each, 2 cores).
//!
//! Usage: [`CholeskyPattern::new`] with the groups of unknowns that will be
//! assembled together returns the slot of every pair in a value array of
//! [`CholeskyPattern::num_values`] entries; [`CholeskyPattern::factor`]
//! factors the assembled values.

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use crate::math::Real;

use super::symbolic::{Ordering, Symbolic};

/// Ordering, block pattern of `P A Pᵀ` (upper triangle by block columns) and
/// symbolic factor of a sparse symmetric matrix.
#[derive(Clone, Debug)]
pub struct CholeskyPattern {
    n: usize,
    /// Block (in elimination order) and place in it of every unknown.
    place: Vec<(usize, usize)>,
    /// Padding places `(block, k)`: unit diagonal.
    padding: Vec<(usize, usize)>,
    /// Block column starts of the upper triangle of `C = P A Pᵀ`.
    c_start: Vec<usize>,
    /// Block row indices of `C` (each column sorted, diagonal last).
    c_rows: Vec<usize>,
    /// Elimination tree, row patterns and block column starts of `L`.
    symbolic: Symbolic,
    /// Block row of every block of `L` ([`Symbolic::column_rows`]).
    l_rows: Vec<usize>,
    /// `(a, b)`: columns `0 … a` (part A) and `a … b` (part B) share no
    /// row of `L`, so they are eliminated in parallel; the columns from `b`
    /// on (the separator) follow. `(nb, nb)` when the factor is serial.
    split: (usize, usize),
}

/// Groups per parallel task of [`CholeskyPattern::new`]'s slots.
const GROUP_CHUNK: usize = 1024;

/// Factors of at least this many blocks are split between two threads at
/// nested dissection's first separator (smaller ones are not worth the
/// synchronisation of every separator row).
const PARALLEL_BLOCKS: usize = 512;

/// A numeric factor `L` (block columns, diagonal block first) with its pattern.
#[derive(Clone, Debug)]
pub struct Cholesky<'a> {
    pattern: &'a CholeskyPattern,
    blocks: Vec<Matrix3<Real>>,
    /// `L_kk⁻¹` of every diagonal block.
    inverse: Vec<Matrix3<Real>>,
}

impl CholeskyPattern {
    /// The pattern of an `n × n` matrix assembled from `groups` (each a list
    /// of unknowns whose every pair is an entry; repeats allowed) and the
    /// diagonal, ordered by nested dissection of the graph on `node_of[i]`
    /// (unknowns of one node form one block). Returns the pattern and the
    /// slots in the value array: for each group, its pairs `(p, q)` with
    /// `p ≤ q` (positions in the group) in order, then the diagonal of
    /// unknowns `0 … n − 1`.
    pub fn new(n: usize, node_of: &[usize], groups: &[&[usize]]) -> (CholeskyPattern, Vec<usize>) {
        // Blocks: the unknowns of each node in chunks of 3.
        let num_nodes = node_of.iter().map(|&v| v + 1).max().unwrap_or(0);
        let mut members = vec![Vec::new(); num_nodes];
        for (i, &v) in node_of.iter().enumerate() {
            members[v].push(i);
        }
        let mut block_of = vec![(0, 0); n];
        let mut sizes = Vec::new();
        for m in members.iter().filter(|m| !m.is_empty()) {
            for chunk in m.chunks(3) {
                for (k, &i) in chunk.iter().enumerate() {
                    block_of[i] = (sizes.len(), k);
                }
                sizes.push(chunk.len());
            }
        }
        let nb = sizes.len();
        let mut adj = vec![Vec::new(); nb];
        let mut blocks = Vec::new();
        for group in groups {
            blocks.clear();
            blocks.extend(group.iter().map(|&i| block_of[i].0));
            blocks.sort_unstable();
            blocks.dedup();
            for (p, &a) in blocks.iter().enumerate() {
                for &b in &blocks[p + 1..] {
                    adj[a].push(b);
                    adj[b].push(a);
                }
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let Ordering {
            perm: order,
            rank,
            top,
        } = Ordering::new(&adj);
        let place: Vec<(usize, usize)> = block_of.iter().map(|&(b, k)| (rank[b], k)).collect();
        let padding = (0..nb)
            .flat_map(|b| {
                let r = rank[b];
                (sizes[b]..3).map(move |k| (r, k))
            })
            .collect();
        // Upper triangle of C by block columns: rows ≤ col, sorted, diagonal last.
        let mut c_start = vec![0; nb + 1];
        let mut c_rows = Vec::new();
        for (k, &b) in order.iter().enumerate() {
            let first = c_rows.len();
            c_rows.extend(adj[b].iter().map(|&a| rank[a]).filter(|&r| r < k));
            c_rows[first..].sort_unstable();
            c_rows.push(k);
            c_start[k + 1] = c_rows.len();
        }
        // The stored block of (row block, column block), row ≤ column.
        let stored = |row: usize, col: usize| {
            let s = c_start[col];
            s + c_rows[s..c_start[col + 1]].partition_point(|&x| x < row)
        };
        // The slot of unknowns (i, j) in `blk`, the stored block of their
        // blocks: (row unknown, column unknown) in it, the diagonal block
        // keeping its upper triangle.
        let slot = |i: usize, j: usize, blk: usize| {
            let (pi, pj) = (place[i], place[j]);
            let ((row, r), (col, c)) = if pi.0 <= pj.0 { (pi, pj) } else { (pj, pi) };
            let (r, c) = if row == col {
                (r.min(c), r.max(c))
            } else {
                (r, c)
            };
            9 * blk + 3 * r + c
        };
        // Groups in parallel chunks; a group's few distinct blocks are
        // looked up pairwise once, not once per pair of unknowns.
        let chunk_slots = |chunk: &[&[usize]]| {
            let mut out = Vec::new();
            let (mut distinct, mut index, mut table) = (Vec::new(), Vec::new(), Vec::new());
            for group in chunk {
                distinct.clear();
                index.clear();
                for &i in group.iter() {
                    let b = place[i].0;
                    let t = distinct.iter().position(|&d| d == b).unwrap_or_else(|| {
                        distinct.push(b);
                        distinct.len() - 1
                    });
                    index.push(t);
                }
                let d = distinct.len();
                table.clear();
                table.resize(d * d, 0);
                for u in 0..d {
                    for v in u..d {
                        let (a, b) = (distinct[u], distinct[v]);
                        let blk = stored(a.min(b), a.max(b));
                        table[u * d + v] = blk;
                        table[v * d + u] = blk;
                    }
                }
                for (p, &i) in group.iter().enumerate() {
                    for (q, &j) in group.iter().enumerate().skip(p) {
                        out.push(slot(i, j, table[index[p] * d + index[q]]));
                    }
                }
            }
            out
        };
        // One chunk stays on this thread (a hand-over to rayon's pool costs more).
        let mut slots = if groups.len() > GROUP_CHUNK {
            let chunks: Vec<Vec<usize>> = groups.par_chunks(GROUP_CHUNK).map(chunk_slots).collect();
            chunks.concat()
        } else {
            chunk_slots(groups)
        };
        slots.extend((0..n).map(|i| slot(i, i, stored(place[i].0, place[i].0))));
        let symbolic = Symbolic::new(&c_start, &c_rows);
        // A and B must share no row of L: no column of A has its parent in B.
        let split = top
            .filter(|_| nb >= PARALLEL_BLOCKS)
            .map(|(a, b)| (a, a + b))
            .filter(|&(a, b)| {
                symbolic.parent[..a]
                    .iter()
                    .all(|p| p.is_none_or(|p| !(a..b).contains(&p)))
            })
            .unwrap_or((nb, nb));
        let pattern = CholeskyPattern {
            n,
            place,
            padding,
            c_start,
            c_rows,
            l_rows: symbolic.column_rows(),
            symbolic,
            split,
        };
        (pattern, slots)
    }

    /// Length of the value array (9 per stored block of `P A Pᵀ`).
    pub fn num_values(&self) -> usize {
        9 * self.c_rows.len()
    }

    /// Stored 3 × 3 blocks of the factor `L`.
    pub fn factor_blocks(&self) -> usize {
        self.symbolic.num_entries()
    }

    /// The product `A x` of the symmetric matrix whose upper triangle (in
    /// the slots returned by [`new`](Self::new)) is `values` with `x`.
    pub fn product(&self, values: &[Real], x: &[Real]) -> Vec<Real> {
        let nb = self.symbolic.num_columns();
        let mut xb = vec![Vector3::zeros(); nb];
        for (i, &(blk, k)) in self.place.iter().enumerate() {
            xb[blk][k] = x[i];
        }
        let block = |p: usize| Matrix3::from_fn(|r, c| values[9 * p + 3 * r + c]);
        let mut y = vec![Vector3::zeros(); nb];
        for k in 0..nb {
            let last = self.c_start[k + 1] - 1;
            for p in self.c_start[k]..last {
                let (b, i) = (block(p), self.c_rows[p]);
                y[i] += b * xb[k];
                y[k] += b.tr_mul(&xb[i]);
            }
            // The diagonal block keeps its upper triangle.
            let u = block(last);
            let full = Matrix3::from_fn(|r, c| if r <= c { u[(r, c)] } else { u[(c, r)] });
            y[k] += full * xb[k];
        }
        self.place.iter().map(|&(blk, k)| y[blk][k]).collect()
    }

    /// Whether the factor is split between two threads: the sizes of the
    /// two parts eliminated in parallel, before the separator.
    pub fn parallel_parts(&self) -> Option<(usize, usize)> {
        let (a, b) = self.split;
        (a < self.symbolic.num_columns()).then_some((a, b - a))
    }

    /// The factor of the matrix whose upper triangle (in the slots returned by
    /// [`new`](Self::new)) is `values`; `None` if it is not positive definite.
    ///
    /// Rows of parts A and B (see [`parallel_parts`](Self::parallel_parts))
    /// are eliminated on two threads; each separator row then takes its
    /// entries in A's and B's columns on two threads, each with its own
    /// accumulator for the separator's rows, and the rest serially.
    pub fn factor(&self, values: &[Real]) -> Option<Cholesky<'_>> {
        // On a worker thread of the pool, so that each separator row's join is cheap.
        in_pool_if(self.parallel_parts().is_some(), || {
            self.factor_on_worker(values)
        })
    }

    fn factor_on_worker(&self, values: &[Real]) -> Option<Cholesky<'_>> {
        let nb = self.symbolic.num_columns();
        let (a_end, b_end) = self.split;
        let block = |p: usize| Matrix3::from_fn(|r, c| values[9 * p + 3 * r + c]);
        let mut pad = vec![[false; 3]; nb];
        for &(b, k) in &self.padding {
            pad[b][k] = true;
        }
        // Column k's diagonal block of C from its upper triangle, padding on the diagonal.
        let diagonal = |k: usize| {
            let upper = block(self.c_start[k + 1] - 1);
            let mut d = Matrix3::from_fn(|r, c| if r <= c { upper[(r, c)] } else { upper[(c, r)] });
            for (i, &padded) in pad[k].iter().enumerate() {
                if padded {
                    d[(i, i)] = 1.0;
                }
            }
            d
        };
        let l_start = &self.symbolic.l_start;
        let nnz = self.symbolic.num_entries();
        let mut blocks: Vec<Matrix3<Real>> = vec![Matrix3::zeros(); nnz];
        let mut inverse: Vec<Matrix3<Real>> = vec![Matrix3::zeros(); nb];
        let mut next: Vec<usize> = l_start[..nb].to_vec();
        let [mut a, mut b, mut sep] =
            self.columns([a_end, b_end], &mut blocks, &mut inverse, &mut next);
        // Rows of A and of B: each touches only its own columns.
        let own_rows = |cols: &mut Columns<'_>, range: std::ops::Range<usize>| {
            if range.is_empty() {
                return Some(());
            }
            let mut x = vec![Matrix3::zeros(); nb];
            for k in range {
                for p in self.c_start[k]..self.c_start[k + 1] - 1 {
                    x[self.c_rows[p]] += block(p);
                }
                let row = self.symbolic.row(k);
                let d = diagonal(k) - cols.eliminate(l_start, row, &mut x);
                cols.close(k, d)?;
            }
            Some(())
        };
        let (done_a, done_b) = join_if(
            b_end > a_end,
            || own_rows(&mut a, 0..a_end),
            || own_rows(&mut b, a_end..b_end),
        );
        done_a?;
        done_b?;
        // Separator rows.
        let mut x = [(); 3].map(|_| vec![Matrix3::zeros(); if b_end < nb { nb } else { 0 }]);
        let mut parts: [Vec<usize>; 3] = Default::default();
        let part_of = |i: usize| usize::from(i >= a_end) + usize::from(i >= b_end);
        for k in b_end..nb {
            parts.iter_mut().for_each(Vec::clear);
            for &i in self.symbolic.row(k) {
                parts[part_of(i)].push(i);
            }
            for p in self.c_start[k]..self.c_start[k + 1] - 1 {
                let r = self.c_rows[p];
                x[part_of(r)][r] += block(p);
            }
            let [xa, xb, xs] = &mut x;
            let (da, db) = rayon::join(
                || a.eliminate(l_start, &parts[0], xa),
                || b.eliminate(l_start, &parts[1], xb),
            );
            for r in b_end..k {
                xs[r] += xa[r] + xb[r];
                xa[r] = Matrix3::zeros();
                xb[r] = Matrix3::zeros();
            }
            let ds = sep.eliminate(l_start, &parts[2], xs);
            sep.close(k, diagonal(k) - da - db - ds)?;
        }
        Some(Cholesky {
            pattern: self,
            blocks,
            inverse,
        })
    }

    /// The columns of `L` cut at `cuts` into three ranges.
    fn columns<'s>(
        &'s self,
        cuts: [usize; 2],
        blocks: &'s mut [Matrix3<Real>],
        inverse: &'s mut [Matrix3<Real>],
        next: &'s mut [usize],
    ) -> [Columns<'s>; 3] {
        let [a, b] = cuts;
        let (la, lb) = (self.symbolic.l_start[a], self.symbolic.l_start[b]);
        let l_rows = &self.l_rows;
        let mut rows = [&l_rows[..la], &l_rows[la..lb], &l_rows[lb..]].into_iter();
        let mut blocks = cut(blocks, la, lb).into_iter();
        let mut inverse = cut(inverse, a, b).into_iter();
        let mut next = cut(next, a, b).into_iter();
        [(0, 0), (a, la), (b, lb)].map(|(first, offset)| Columns {
            first,
            offset,
            rows: rows.next().expect("three parts"),
            blocks: blocks.next().expect("three parts"),
            inverse: inverse.next().expect("three parts"),
            next: next.next().expect("three parts"),
        })
    }
}

/// A range of the factor's columns, borrowed apart from the others.
struct Columns<'s> {
    /// First column.
    first: usize,
    /// Position of the first column's first block in the whole factor.
    offset: usize,
    /// Block rows of this range's blocks (the pattern's `l_rows`).
    rows: &'s [usize],
    blocks: &'s mut [Matrix3<Real>],
    inverse: &'s mut [Matrix3<Real>],
    /// Next free position (in the whole factor) of every column.
    next: &'s mut [usize],
}

impl Columns<'_> {
    /// Row `k`'s step of the up-looking factorisation in the columns
    /// `stack` (all in this range, descendants first): `Z_i = L_ii⁻¹ X_i`,
    /// `X_r −= L_ri Z_i` for the rows already in column `i`, `L_ki = Z_iᵀ`.
    /// Returns `Σ Z_iᵀ Z_i`, to subtract from the diagonal block.
    fn eliminate(
        &mut self,
        l_start: &[usize],
        stack: &[usize],
        x: &mut [Matrix3<Real>],
    ) -> Matrix3<Real> {
        let mut zz = Matrix3::zeros();
        for &i in stack {
            let c = i - self.first;
            let z = self.inverse[c] * x[i];
            x[i] = Matrix3::zeros();
            let end = self.next[c] - self.offset;
            for p in l_start[i] + 1 - self.offset..end {
                x[self.rows[p]] -= self.blocks[p] * z;
            }
            zz += z.transpose() * z;
            self.blocks[end] = z.transpose();
            self.next[c] += 1;
        }
        zz
    }

    /// Sets column `k`'s diagonal block to the Cholesky factor of `d`;
    /// `None` if `d` is not positive definite.
    fn close(&mut self, k: usize, d: Matrix3<Real>) -> Option<()> {
        let l = d.cholesky()?.l();
        if !l.iter().all(|v| v.is_finite()) {
            return None;
        }
        let c = k - self.first;
        self.inverse[c] = l.try_inverse()?;
        let at = self.next[c] - self.offset;
        self.blocks[at] = l;
        self.next[c] += 1;
        Some(())
    }
}

impl Cholesky<'_> {
    /// The solution `x` of `A x = b`, by the two triangular solves; the
    /// columns of parts A and B on two threads (forward before the
    /// separator, backward after it).
    pub fn solution(&self, b: &[Real]) -> Vec<Real> {
        in_pool_if(self.pattern.parallel_parts().is_some(), || {
            self.solution_on_worker(b)
        })
    }

    fn solution_on_worker(&self, b: &[Real]) -> Vec<Real> {
        let p = self.pattern;
        let nb = p.symbolic.num_columns();
        let (a_end, b_end) = p.split;
        let mut x: Vec<Vector3<Real>> = vec![Vector3::zeros(); nb];
        for (i, &(blk, k)) in p.place.iter().enumerate() {
            x[blk][k] = b[i];
        }
        let (xa, rest) = x.split_at_mut(a_end);
        let (xb, xs) = rest.split_at_mut(b_end - a_end);
        // Forward: A and B each push their separator rows into an accumulator.
        let parallel = b_end > a_end;
        let (sa, sb) = join_if(
            parallel,
            || self.forward(0, xa, b_end),
            || self.forward(a_end, xb, b_end),
        );
        for ((v, ua), ub) in xs.iter_mut().zip(&sa).zip(&sb) {
            *v += ua + ub;
        }
        self.forward(b_end, xs, nb);
        self.backward(b_end, xs, &[]);
        join_if(
            parallel,
            || self.backward(0, xa, xs),
            || self.backward(a_end, xb, xs),
        );
        (0..p.n).map(|i| x[p.place[i].0][p.place[i].1]).collect()
    }

    /// Forward substitution over the columns `first …` held in `x`; updates
    /// of rows from `sep` on go to the returned accumulator (indexed from
    /// `sep`).
    fn forward(&self, first: usize, x: &mut [Vector3<Real>], sep: usize) -> Vec<Vector3<Real>> {
        let l_start = &self.pattern.symbolic.l_start;
        let mut out = vec![Vector3::zeros(); l_start.len() - 1 - sep];
        for c in 0..x.len() {
            let j = first + c;
            let y = self.inverse[j] * x[c];
            x[c] = y;
            for q in l_start[j] + 1..l_start[j + 1] {
                let (r, u) = (self.pattern.l_rows[q], self.blocks[q] * y);
                if r < sep {
                    x[r - first] -= u;
                } else {
                    out[r - sep] -= u;
                }
            }
        }
        out
    }

    /// Backward substitution over the columns `first …` held in `x`; rows
    /// beyond them are read from `sep` (the separator's solved values).
    fn backward(&self, first: usize, x: &mut [Vector3<Real>], sep: &[Vector3<Real>]) {
        let l_start = &self.pattern.symbolic.l_start;
        let end = first + x.len();
        let sep_first = self.pattern.split.1;
        for c in (0..x.len()).rev() {
            let j = first + c;
            let mut v = x[c];
            for q in l_start[j] + 1..l_start[j + 1] {
                let r = self.pattern.l_rows[q];
                let xr = if r < end {
                    x[r - first]
                } else {
                    sep[r - sep_first]
                };
                v -= self.blocks[q].tr_mul(&xr);
            }
            x[c] = self.inverse[j].tr_mul(&v);
        }
    }
}
/// `s` cut at `a ≤ b` into `[..a, a..b, b..]`.
fn cut<T>(s: &mut [T], a: usize, b: usize) -> [&mut [T]; 3] {
    let (first, rest) = s.split_at_mut(a);
    let (second, third) = rest.split_at_mut(b - a);
    [first, second, third]
}

/// `f()` on a worker thread of rayon's pool if `parallel` (so that the joins
/// inside it are cheap), else on this one.
fn in_pool_if<R: Send>(parallel: bool, f: impl FnOnce() -> R + Send) -> R {
    if parallel { rayon::scope(|_| f()) } else { f() }
}

/// `(a(), b())`, on two threads (`rayon::join`) if `parallel`, else in turn
/// on this one (a join from outside rayon's pool costs a hand-over to it).
pub(super) fn join_if<A: Send, B: Send>(
    parallel: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if parallel {
        rayon::join(a, b)
    } else {
        (a(), b())
    }
}

//! A small sparse Cholesky factorisation `P A Pᵀ = L Lᵀ` for the
//! Gauss-Newton systems of fine tuning (symmetric positive definite, a few
//! thousand unknowns, the same pattern at every step).
//!
//! Up-looking algorithm (Davis, *Direct Methods for Sparse Linear Systems*,
//! 2006, §4.2 and §4.6: elimination tree, row patterns by `ereach`), with a
//! minimum-degree ordering of a node graph (`min_degree`). Written here
//! rather than adding faer because the systems are small and the pattern,
//! ordering and symbolic factor are computed once per solve and reused.
//!
//! Usage: [`CholeskyPattern::new`] with the list of `(i, j)` positions that
//! will be assembled (in any orientation, repeats allowed) returns, for each
//! listed position, its slot in [`CholeskyPattern::values`]-sized storage;
//! [`CholeskyPattern::factor`] factors the assembled values.

use crate::math::Real;

use super::min_degree::min_degree;

/// Ordering, pattern of `P A Pᵀ` (upper triangle by columns) and symbolic
/// factor of a sparse symmetric matrix.
#[derive(Clone, Debug)]
pub struct CholeskyPattern {
    n: usize,
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// Column starts of the upper triangle of `C = P A Pᵀ`.
    c_start: Vec<usize>,
    /// Row indices of `C` (each column sorted, diagonal last).
    c_rows: Vec<usize>,
    /// Elimination tree of `C`.
    parent: Vec<Option<usize>>,
    /// Column starts of `L`.
    l_start: Vec<usize>,
}

/// A numeric factor `L` (columns, diagonal first) with its pattern.
#[derive(Clone, Debug)]
pub struct Cholesky<'a> {
    pattern: &'a CholeskyPattern,
    rows: Vec<usize>,
    values: Vec<Real>,
}

impl CholeskyPattern {
    /// The pattern of an `n × n` matrix with entries at `positions` (each
    /// `(i, j)` stands for both `(i, j)` and `(j, i)`; the diagonal is always
    /// included), ordered by minimum degree of the graph on `node_of[i]`
    /// (unknowns of one node stay together). Returns the pattern and, for
    /// every entry of `positions`, its slot in the value array.
    pub fn new(
        n: usize,
        node_of: &[usize],
        positions: &[(usize, usize)],
    ) -> (CholeskyPattern, Vec<usize>) {
        let num_nodes = node_of.iter().map(|&v| v + 1).max().unwrap_or(0);
        let mut node_adj = vec![Vec::new(); num_nodes];
        for &(i, j) in positions {
            let (a, b) = (node_of[i], node_of[j]);
            if a != b {
                node_adj[a].push(b);
                node_adj[b].push(a);
            }
        }
        for a in &mut node_adj {
            a.sort_unstable();
            a.dedup();
        }
        let node_order = min_degree(&node_adj);
        let mut node_rank = vec![0; num_nodes];
        for (r, &v) in node_order.iter().enumerate() {
            node_rank[v] = r;
        }
        let mut perm: Vec<usize> = (0..n).collect();
        perm.sort_by_key(|&i| (node_rank[node_of[i]], i));
        let mut inv = vec![0; n];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        // Upper triangle of C by columns: (row ≤ col).
        let mut entries: Vec<(usize, usize)> = positions
            .iter()
            .map(|&(i, j)| {
                let (a, b) = (inv[i], inv[j]);
                (a.max(b), a.min(b))
            })
            .chain((0..n).map(|k| (k, k)))
            .collect();
        entries.sort_unstable();
        entries.dedup();
        let mut c_start = vec![0; n + 1];
        for &(col, _) in &entries {
            c_start[col + 1] += 1;
        }
        for k in 0..n {
            c_start[k + 1] += c_start[k];
        }
        let c_rows: Vec<usize> = entries.iter().map(|&(_, row)| row).collect();
        let slots = positions
            .iter()
            .map(|&(i, j)| {
                let (a, b) = (inv[i], inv[j]);
                let (col, row) = (a.max(b), a.min(b));
                let s = c_start[col];
                s + c_rows[s..c_start[col + 1]].partition_point(|&r| r < row)
            })
            .collect();
        let parent = elimination_tree(n, &c_start, &c_rows);
        let mut counts = vec![1usize; n];
        let mut mark = vec![usize::MAX; n];
        let mut stack = Vec::new();
        for k in 0..n {
            row_pattern(k, &c_start, &c_rows, &parent, &mut mark, &mut stack);
            for &i in &stack {
                counts[i] += 1;
            }
        }
        let mut l_start = vec![0; n + 1];
        for k in 0..n {
            l_start[k + 1] = l_start[k] + counts[k];
        }
        let pattern = CholeskyPattern {
            n,
            perm,
            c_start,
            c_rows,
            parent,
            l_start,
        };
        (pattern, slots)
    }

    /// Number of stored values of `P A Pᵀ` (the length of the value array).
    pub fn num_values(&self) -> usize {
        self.c_rows.len()
    }

    /// Nonzeros of the factor `L`.
    pub fn factor_nonzeros(&self) -> usize {
        self.l_start[self.n]
    }

    /// The factor of the matrix whose upper triangle (in the slots returned by
    /// [`new`](Self::new)) is `values`; `None` if it is not positive definite.
    pub fn factor(&self, values: &[Real]) -> Option<Cholesky<'_>> {
        let n = self.n;
        let nnz = self.l_start[n];
        let mut rows = vec![0; nnz];
        let mut lx = vec![0.0; nnz];
        let mut next: Vec<usize> = self.l_start[..n].to_vec();
        let mut x = vec![0.0; n];
        let mut mark = vec![usize::MAX; n];
        let mut stack = Vec::new();
        for k in 0..n {
            row_pattern(
                k,
                &self.c_start,
                &self.c_rows,
                &self.parent,
                &mut mark,
                &mut stack,
            );
            for p in self.c_start[k]..self.c_start[k + 1] {
                x[self.c_rows[p]] += values[p];
            }
            let mut d = x[k];
            x[k] = 0.0;
            // `stack` is in topological order (descendants first).
            for &i in &stack {
                let lki = x[i] / lx[self.l_start[i]];
                x[i] = 0.0;
                for p in self.l_start[i] + 1..next[i] {
                    x[rows[p]] -= lx[p] * lki;
                }
                d -= lki * lki;
                rows[next[i]] = k;
                lx[next[i]] = lki;
                next[i] += 1;
            }
            if !(d > 0.0 && d.is_finite()) {
                return None;
            }
            rows[next[k]] = k;
            lx[next[k]] = d.sqrt();
            next[k] += 1;
        }
        Some(Cholesky {
            pattern: self,
            rows,
            values: lx,
        })
    }
}

impl Cholesky<'_> {
    /// The solution `x` of `A x = b`.
    pub fn solution(&self, b: &[Real]) -> Vec<Real> {
        let p = self.pattern;
        let mut x: Vec<Real> = p.perm.iter().map(|&i| b[i]).collect();
        for j in 0..p.n {
            let s = p.l_start[j];
            x[j] /= self.values[s];
            let xj = x[j];
            for q in s + 1..p.l_start[j + 1] {
                x[self.rows[q]] -= self.values[q] * xj;
            }
        }
        for j in (0..p.n).rev() {
            let s = p.l_start[j];
            let mut v = x[j];
            for q in s + 1..p.l_start[j + 1] {
                v -= self.values[q] * x[self.rows[q]];
            }
            x[j] = v / self.values[s];
        }
        let mut out = vec![0.0; p.n];
        for (new, &old) in p.perm.iter().enumerate() {
            out[old] = x[new];
        }
        out
    }
}

/// Elimination tree of a matrix given by its upper triangle by columns
/// (Davis 2006, §4.1, with path compression).
fn elimination_tree(n: usize, start: &[usize], rows: &[usize]) -> Vec<Option<usize>> {
    let mut parent = vec![None; n];
    let mut ancestor: Vec<Option<usize>> = vec![None; n];
    for k in 0..n {
        for &row in &rows[start[k]..start[k + 1]] {
            let mut i = Some(row);
            while let Some(j) = i.filter(|&j| j < k) {
                let next = ancestor[j];
                ancestor[j] = Some(k);
                if next.is_none() {
                    parent[j] = Some(k);
                }
                i = next;
            }
        }
    }
    parent
}

/// The pattern of row `k` of `L` (columns `< k`) in topological order, into
/// `stack` (Davis 2006, §4.2 `ereach`). `mark` holds `k` for visited nodes.
fn row_pattern(
    k: usize,
    start: &[usize],
    rows: &[usize],
    parent: &[Option<usize>],
    mark: &mut [usize],
    stack: &mut Vec<usize>,
) {
    stack.clear();
    mark[k] = k;
    let mut path = Vec::new();
    for &row in &rows[start[k]..start[k + 1]] {
        let mut i = row;
        path.clear();
        while mark[i] != k {
            path.push(i);
            mark[i] = k;
            match parent[i] {
                Some(p) => i = p,
                None => break,
            }
        }
        // Each path ancestor-first; the final reversal lists later paths
        // (which end below earlier ones) first, each child-first.
        stack.extend(path.iter().rev());
    }
    stack.reverse();
}

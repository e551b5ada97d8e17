//! The symbolic phase of a sparse Cholesky factorisation `P A Pᵀ = L Lᵀ`,
//! written once for both numeric factors (scalar entries,
//! [`SparseCholesky`](super::SparseCholesky); 3 × 3 blocks,
//! [`CholeskyPattern`](super::CholeskyPattern)): the fill-reducing order
//! of `A`'s graph ([`Ordering`], nested dissection with minimum degree on
//! small parts), the elimination tree of `C = P A Pᵀ` and the pattern of
//! every row of `L` by `ereach`, in an order the up-looking numeric phase
//! can eliminate in (Davis, *Direct Methods for Sparse Linear Systems*,
//! 2006, §4.1 (etree, with path compression) and §4.2 (`ereach`)).
//!
//! The caller gives the upper triangle of `C` by columns (rows ≤ column,
//! the diagonal may be among them); the order of the rows within a column
//! fixes the order of each row pattern and so the order of the numeric
//! phase's arithmetic.

use super::nested_dissection;

/// A fill-reducing elimination order of a graph (its nodes are `A`'s rows,
/// or its blocks of rows).
#[derive(Clone, Debug)]
pub(crate) struct Ordering {
    /// `perm[k]`: the node eliminated `k`-th.
    pub(crate) perm: Vec<usize>,
    /// `rank[v]`: when node `v` is eliminated (the inverse of `perm`).
    pub(crate) rank: Vec<usize>,
    /// The sizes of the two parts that nested dissection's first separator
    /// splits the graph into (eliminated first, in this order, then the
    /// separator); `None` when the graph was not split.
    pub(crate) top: Option<(usize, usize)>,
}

impl Ordering {
    /// Nested dissection of the graph with the (sorted, duplicate-free,
    /// loop-free) neighbour lists `adj`.
    pub(crate) fn new(adj: &[Vec<usize>]) -> Ordering {
        let (perm, top) = nested_dissection(adj);
        let mut rank = vec![0; perm.len()];
        for (k, &v) in perm.iter().enumerate() {
            rank[v] = k;
        }
        Ordering { perm, rank, top }
    }
}

/// The elimination tree and the pattern of `L` for one pattern of `C`.
#[derive(Clone, Debug)]
pub(crate) struct Symbolic {
    /// Parent of every column of `L` in the elimination tree.
    pub(crate) parent: Vec<Option<usize>>,
    /// Start of every row's pattern in `r_cols` (one more than rows).
    r_start: Vec<usize>,
    /// Every row of `L` below the diagonal: its columns in topological
    /// order (descendants before ancestors).
    r_cols: Vec<usize>,
    /// Start of every column of `L` (its diagonal included) in a column-wise
    /// layout of the factor (one more than columns).
    pub(crate) l_start: Vec<usize>,
}

impl Symbolic {
    /// The elimination tree and row patterns of the factor of `C`, given by
    /// its upper triangle: column `k` holds the rows
    /// `c_rows[c_start[k]..c_start[k + 1]]`, each at most `k`.
    pub(crate) fn new(c_start: &[usize], c_rows: &[usize]) -> Symbolic {
        let n = c_start.len() - 1;
        let parent = elimination_tree(n, c_start, c_rows);
        let mut mark = vec![usize::MAX; n];
        let mut stack = Vec::new();
        let mut path = Vec::new();
        let mut r_start = Vec::with_capacity(n + 1);
        r_start.push(0);
        let mut r_cols = Vec::new();
        let mut counts = vec![1usize; n];
        for k in 0..n {
            let rows = &c_rows[c_start[k]..c_start[k + 1]];
            ereach(k, rows, &parent, &mut mark, &mut path, &mut stack);
            for &i in &stack {
                counts[i] += 1;
            }
            r_cols.extend_from_slice(&stack);
            r_start.push(r_cols.len());
        }
        let mut l_start = vec![0; n + 1];
        for j in 0..n {
            l_start[j + 1] = l_start[j] + counts[j];
        }
        Symbolic {
            parent,
            r_start,
            r_cols,
            l_start,
        }
    }

    /// Columns of `L`.
    pub(crate) fn num_columns(&self) -> usize {
        self.l_start.len() - 1
    }

    /// Entries (or blocks) of `L`, the diagonal included.
    pub(crate) fn num_entries(&self) -> usize {
        self.l_start[self.num_columns()]
    }

    /// The columns `< k` of row `k` of `L`, descendants before ancestors in
    /// the elimination tree (the order in which the up-looking phase
    /// eliminates them).
    pub(crate) fn row(&self, k: usize) -> &[usize] {
        &self.r_cols[self.r_start[k]..self.r_start[k + 1]]
    }

    /// The rows of `L` by columns, laid out by `l_start`: each column's
    /// diagonal first, then its rows below it in increasing order.
    pub(crate) fn column_rows(&self) -> Vec<usize> {
        let n = self.num_columns();
        let mut rows = vec![0; self.num_entries()];
        let mut next: Vec<usize> = self.l_start[..n].iter().map(|&s| s + 1).collect();
        for k in 0..n {
            rows[self.l_start[k]] = k;
            for &i in self.row(k) {
                rows[next[i]] = k;
                next[i] += 1;
            }
        }
        rows
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
/// `stack`, from the rows of column `k` of `C` (Davis 2006, §4.2 `ereach`):
/// from each row up the elimination tree to a node already visited; later
/// paths first, each child-first. `mark` holds `k` for visited nodes.
fn ereach(
    k: usize,
    rows: &[usize],
    parent: &[Option<usize>],
    mark: &mut [usize],
    path: &mut Vec<usize>,
    stack: &mut Vec<usize>,
) {
    stack.clear();
    mark[k] = k;
    for &row in rows {
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

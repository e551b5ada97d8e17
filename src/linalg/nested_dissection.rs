//! Nested-dissection ordering of a graph for sparse Cholesky (George 1973;
//! Davis 2006, §7.6), with breadth-first level sets as separators.
//!
//! A part is split by the middle level of a breadth-first search from a
//! pseudo-peripheral node (a level separates the levels before it from those
//! after it, because graph edges join only neighbouring levels); both sides
//! are ordered recursively and the separator last. Parts of at most
//! [`LEAF`] nodes, or too shallow to split, are ordered by minimum degree.
//! Used by both sparse Cholesky solvers (fine tuning's and the dynamic
//! surfaces'). On the mesh-like graphs of surface fine tuning this costs a few
//! breadth-first searches instead of the clique merges of minimum degree
//! over the whole graph.

use std::collections::VecDeque;

use super::min_degree::min_degree;

/// Parts at most this large are ordered by minimum degree.
pub const LEAF: usize = 64;

/// An elimination order (a permutation of `0 … n − 1`) of the graph with
/// adjacency lists `adj` (symmetric, without self loops), and the sizes
/// `(a, b)` of the first split: the order is part A (`a` nodes), then part B
/// (`b` nodes), then the separator, and no edge joins A and B; `None` when
/// the graph was ordered whole.
pub fn nested_dissection(adj: &[Vec<usize>]) -> (Vec<usize>, Option<(usize, usize)>) {
    let n = adj.len();
    let mut order = Vec::with_capacity(n);
    let mut part_of = vec![usize::MAX; n];
    let mut level = vec![usize::MAX; n];
    let mut next_id = 0;
    // A stack: a part pushes its separator, then side B, then side A, so that
    // A is ordered first, then B, then the separator.
    let mut work = vec![Item::Part((0..n).collect())];
    let mut split = None;
    while let Some(item) = work.pop() {
        let part = match item {
            Item::Emit(nodes) => {
                order.extend(nodes);
                continue;
            }
            Item::Part(part) => part,
        };
        if part.is_empty() {
            continue;
        }
        let id = next_id;
        next_id += 1;
        for &v in &part {
            part_of[v] = id;
        }
        if part.len() <= LEAF {
            order.extend(leaf_order(&part, adj, &part_of, id));
            continue;
        }
        let reached = bfs(part[0], adj, &part_of, id, &mut level);
        if reached.len() < part.len() {
            // Several components: the reached one and the rest, apart.
            let rest: Vec<usize> = part
                .iter()
                .copied()
                .filter(|&v| level[v] == usize::MAX)
                .collect();
            reset(&reached, &mut level);
            if id == 0 {
                split = Some((reached.len(), rest.len()));
            }
            work.push(Item::Part(rest));
            work.push(Item::Part(reached));
            continue;
        }
        reset(&reached, &mut level);
        // Levels from a pseudo-peripheral node (the last one reached).
        let start = reached[reached.len() - 1];
        let nodes = bfs(start, adj, &part_of, id, &mut level);
        let lv: Vec<usize> = nodes.iter().map(|&v| level[v]).collect();
        reset(&nodes, &mut level);
        let depth = lv[lv.len() - 1] + 1;
        if depth < 3 {
            order.extend(leaf_order(&part, adj, &part_of, id));
            continue;
        }
        // Discovery order has non-decreasing levels: the median node's level.
        let mid = lv[lv.len() / 2].clamp(1, depth - 2);
        let pick = |keep: fn(usize, usize) -> bool| -> Vec<usize> {
            nodes
                .iter()
                .zip(&lv)
                .filter(|&(_, &l)| keep(l, mid))
                .map(|(&v, _)| v)
                .collect()
        };
        let (before, after) = (pick(|l, m| l < m), pick(|l, m| l > m));
        if id == 0 {
            split = Some((before.len(), after.len()));
        }
        work.push(Item::Emit(pick(|l, m| l == m)));
        work.push(Item::Part(after));
        work.push(Item::Part(before));
    }
    (order, split)
}

/// Clears the levels of `nodes`.
fn reset(nodes: &[usize], level: &mut [usize]) {
    for &v in nodes {
        level[v] = usize::MAX;
    }
}

/// Work of [`nested_dissection`].
enum Item {
    Part(Vec<usize>),
    Emit(Vec<usize>),
}

/// Breadth-first search from `start` inside part `id`: the nodes in order of
/// discovery, with `level` set for each (the caller resets it).
fn bfs(
    start: usize,
    adj: &[Vec<usize>],
    part_of: &[usize],
    id: usize,
    level: &mut [usize],
) -> Vec<usize> {
    let mut out = vec![start];
    level[start] = 0;
    let mut queue = VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for &u in &adj[v] {
            if part_of[u] == id && level[u] == usize::MAX {
                level[u] = level[v] + 1;
                out.push(u);
                queue.push_back(u);
            }
        }
    }
    out
}

/// Minimum-degree order of the subgraph induced by `part`.
fn leaf_order(part: &[usize], adj: &[Vec<usize>], part_of: &[usize], id: usize) -> Vec<usize> {
    let local: std::collections::HashMap<usize, usize> =
        part.iter().enumerate().map(|(i, &v)| (v, i)).collect();
    let sub: Vec<Vec<usize>> = part
        .iter()
        .map(|&v| {
            let mut a: Vec<usize> = adj[v]
                .iter()
                .filter(|&&u| part_of[u] == id)
                .map(|u| local[u])
                .collect();
            a.sort_unstable();
            a.dedup();
            a
        })
        .collect();
    min_degree(&sub).into_iter().map(|i| part[i]).collect()
}

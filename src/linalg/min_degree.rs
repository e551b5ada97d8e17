//! Minimum-degree ordering of a graph for sparse Cholesky (Tinney and
//! Walker 1967; Davis 2006, §7.1): repeatedly eliminate a node of least
//! current degree and join its neighbours into a clique. This is the plain
//! form on the explicit elimination graph (no quotient graph, no
//! approximate degrees), adequate for the few thousand nodes of a
//! fine-tuning problem; ties go to the lowest index, so the order is
//! deterministic.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// An elimination order (a permutation of `0 … n − 1`) of the graph with
/// adjacency lists `adj` (symmetric, sorted, without self loops).
pub fn min_degree(adj: &[Vec<usize>]) -> Vec<usize> {
    let n = adj.len();
    let mut graph: Vec<Vec<usize>> = adj.to_vec();
    let mut done = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(usize, usize)>> =
        (0..n).map(|v| Reverse((graph[v].len(), v))).collect();
    let mut order = Vec::with_capacity(n);
    let mut merged = Vec::new();
    while let Some(Reverse((deg, v))) = heap.pop() {
        if done[v] || deg != graph[v].len() {
            continue;
        }
        done[v] = true;
        order.push(v);
        let clique = std::mem::take(&mut graph[v]);
        for &u in &clique {
            // adj(u) ← adj(u) ∪ clique \ {u, v}: merge of two sorted lists.
            let mut old = std::mem::take(&mut graph[u]);
            merged.clear();
            let (mut a, mut b) = (0, 0);
            while a < old.len() || b < clique.len() {
                let x = match (old.get(a), clique.get(b)) {
                    (Some(&p), Some(&q)) if p == q => {
                        a += 1;
                        b += 1;
                        p
                    }
                    (Some(&p), Some(&q)) if p < q => {
                        a += 1;
                        p
                    }
                    (Some(&p), None) => {
                        a += 1;
                        p
                    }
                    (_, Some(&q)) => {
                        b += 1;
                        q
                    }
                    (None, None) => break,
                };
                if x != u && x != v {
                    merged.push(x);
                }
            }
            // Swap buffers: `u` keeps the merge, `merged` reuses the old list.
            old.clear();
            std::mem::swap(&mut old, &mut merged);
            graph[u] = old;
            heap.push(Reverse((graph[u].len(), u)));
        }
    }
    order
}

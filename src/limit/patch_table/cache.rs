//! The quadtree leaves shared by the patch tables of related meshes.

use super::{Leaf, PatchTable, TREE_DEPTH, Tree};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use crate::limit::param::{CORNERS, child_frame, mat_mul, mat_vec};
use crate::limit::patch::{LocalPatch, Ring};

/// Quadtree leaves by the one-ring's local structure
/// (`Ring::shape_key`): irregular faces with the same structure
/// (most faces at extraordinary vertices of one valence) share their
/// weights, which depend on nothing else. Every [`PatchTable`] keeps one;
/// tables built one after the other over related meshes (the levels of a
/// fit, whose refinements keep most structures) can share one through
/// [`PatchTable::with_quadtrees`], which a clone of the cache does.
#[derive(Clone, Default)]
pub struct QuadtreeCache(Arc<Mutex<Shapes>>);

/// Leaves by `Ring::shape_key`.
pub(super) type Shapes = HashMap<Vec<u64>, Arc<Shape>>;

/// The quadtree leaves of one local structure and the structure's number
/// in its [`QuadtreeCache`] (the order it was first met in).
pub(super) struct Shape {
    pub(super) id: usize,
    pub(super) leaves: Vec<Leaf>,
}

impl std::fmt::Debug for QuadtreeCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.0.lock().map_or(0, |s| s.len());
        write!(f, "QuadtreeCache({n} structures)")
    }
}

impl PatchTable {
    /// The quadtree of irregular level-`L` face `f` (see module docs).
    /// The local patch is built only for a structure not met before; the
    /// first structure stored under a key is the one every tree shares.
    pub(super) fn tree(&self, f: usize) -> Tree {
        let ring = Ring::of(&self.level, f);
        let key = ring.shape_key(&self.level, &self.sharp);
        let cols = ring.map.clone();
        // A poisoned lock (a panic elsewhere while it was held) still
        // guards a consistent map: an insertion is one call.
        let shapes = || self.shapes.0.lock().unwrap_or_else(|e| e.into_inner());
        let cached = shapes().get(&key).cloned();
        let shape = cached.unwrap_or_else(|| {
            let leaves = Self::leaves(LocalPatch::of_ring(&self.level, &self.sharp, ring));
            let mut shapes = shapes();
            let id = shapes.len();
            shapes
                .entry(key)
                .or_insert_with(|| Arc::new(Shape { id, leaves }))
                .clone()
        });
        Tree {
            cols,
            points: shape.leaves.iter().map(|_| OnceLock::new()).collect(),
            shape,
        }
    }

    /// The quadtree leaves of local patch `root` (weights over its `cols`).
    fn leaves(root: LocalPatch) -> Vec<Leaf> {
        let mut leaves = Vec::new();
        let mut stack = vec![(root, [[1.0, 0.0], [0.0, 1.0]], [0.0, 0.0], 0)];
        while let Some((patch, jac, off, depth)) = stack.pop() {
            if depth == TREE_DEPTH {
                leaves.push(Leaf {
                    jac,
                    off,
                    grid: None,
                    cell: Some(Box::new(patch)),
                });
                continue;
            }
            let refined = patch.refined();
            for (k, o) in CORNERS.iter().enumerate() {
                let (_, m) = child_frame(k, [0.0, 0.0]);
                let cj = mat_mul(m, jac);
                let co = mat_vec(m, [off[0] - o[0], off[1] - o[1]]);
                let cf = patch.child_face(k);
                if refined.is_regular(cf) {
                    leaves.push(Leaf {
                        jac: cj,
                        off: co,
                        grid: Some(refined.grid_rows(cf)),
                        cell: None,
                    });
                } else {
                    stack.push((refined.extract(cf), cj, co, depth + 1));
                }
            }
        }
        leaves
    }
}

//! Limit stencils of a [`PatchTable`]: the weights of the limit position
//! and its derivatives over the control points (rows of the Jacobian).

use super::{PatchTable, Tree};
use crate::math::Real;
use crate::stencil::{RowBuilder, StencilTable};

use crate::limit::bspline::{patch_weights, position_weights};
use crate::limit::local_eval::evaluate_face;
use crate::limit::param::chain;
use crate::limit::patch::SampleStencil;

impl PatchTable {
    /// Weights of the limit position and its `(s, t)` derivatives at
    /// `(s, t)` of patch `f` over the level-`L` vertices (compose with
    /// [`to_level`](Self::to_level) for weights over the control points,
    /// or transform a matrix assembled over level `L` as `Sᵀ M S`).
    pub fn stencil(&self, f: usize, st: [Real; 2]) -> SampleStencil {
        let patch = &self.patches[f];
        let w = patch_weights(st[0].clamp(0.0, 1.0), st[1].clamp(0.0, 1.0));
        if patch.regular {
            let mut b: [RowBuilder; 6] = Default::default();
            for i in 0..16 {
                let (cols, ws) = self.grid_table.row(16 * f + i);
                for (bq, wq) in b.iter_mut().zip(&w) {
                    if wq[i] != 0.0 {
                        for (&c, &x) in cols.iter().zip(ws) {
                            bq.add(c, wq[i] * x);
                        }
                    }
                }
            }
            return builders_to_stencil(&b);
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        self.tree_stencil(tree, f, st)
    }

    /// [`stencil`](Self::stencil) at several points of patch `f`. An
    /// irregular patch's quadtree is used if [`stencil`](Self::stencil) or an
    /// evaluation has cached it, and otherwise built for this call alone and
    /// dropped (its weights stay shared with faces of the same structure):
    /// the sample sets of the dynamics ([`crate::dynamics`]) visit every
    /// patch once, and caching every patch's tree would hold its leaves'
    /// control points for the rest of the table's life.
    pub fn stencils(&self, f: usize, sts: &[[Real; 2]]) -> Vec<SampleStencil> {
        let patch = &self.patches[f];
        if patch.regular {
            return sts.iter().map(|&st| self.stencil(f, st)).collect();
        }
        let local;
        let tree = match patch.tree.get() {
            Some(tree) => tree,
            None => {
                local = self.tree(f);
                &local
            }
        };
        sts.iter()
            .map(|&st| self.tree_stencil(tree, f, st))
            .collect()
    }

    /// The stencil at `(s, t)` of irregular patch `f` from its quadtree.
    fn tree_stencil(&self, tree: &Tree, f: usize, st: [Real; 2]) -> SampleStencil {
        let nc = tree.cols.len();
        if let Some((_, leaf, rows, x)) = tree.leaf_at(st) {
            let w = patch_weights(x[0], x[1]);
            let local: [Vec<Real>; 6] = std::array::from_fn(|q| {
                let mut out = vec![0.0; nc];
                for i in 0..16 {
                    for (o, &r) in out.iter_mut().zip(&rows[i * nc..(i + 1) * nc]) {
                        *o += w[q][i] * r;
                    }
                }
                out
            });
            let mut weights: [Vec<Real>; 6] = std::array::from_fn(|_| vec![0.0; nc]);
            for k in 0..nc {
                weights[0][k] = local[0][k];
                let d = chain([1, 2, 3, 4, 5].map(|q| local[q][k]), leaf.jac);
                for q in 0..5 {
                    weights[q + 1][k] = d[q];
                }
            }
            return SampleStencil {
                cols: tree.cols.clone(),
                weights,
            };
        }
        evaluate_face(&self.level, &self.sharp, f, st[0], st[1])
    }

    /// The position row of [`stencil`](Self::stencil) alone (cheaper):
    /// columns (level-`L` vertices) and weights.
    pub fn position_stencil(&self, f: usize, st: [Real; 2]) -> (Vec<u32>, Vec<Real>) {
        let mut b = RowBuilder::default();
        self.visit_position_weights(f, st, |c, w| b.add(c, w));
        b.entries().unzip()
    }

    /// The terms of [`position_stencil`](Self::position_stencil) handed to
    /// `visit(column, weight)` one by one (a column may come more than once;
    /// its weights add), without allocating except in the innermost cell at
    /// an irregular vertex.
    pub fn visit_position_weights(
        &self,
        f: usize,
        st: [Real; 2],
        mut visit: impl FnMut(u32, Real),
    ) {
        self.visit_position_terms(f, st, |_, c, w| visit(c, w));
    }

    /// The level-`L` columns of patch `f`'s position stencils, in a fixed
    /// order: [`visit_position_terms`](Self::visit_position_terms) names
    /// its terms by their places in this list. Builds (and keeps) an
    /// irregular patch's quadtree.
    pub fn position_columns(&self, f: usize) -> &[u32] {
        let patch = &self.patches[f];
        if patch.regular {
            let g = &self.grid_table;
            return &g.indices[g.offsets[16 * f]..g.offsets[16 * f + 16]];
        }
        &patch.tree.get_or_init(|| self.tree(f)).cols
    }

    /// [`visit_position_weights`](Self::visit_position_weights), also
    /// handing each term's place in [`position_columns`](Self::position_columns)
    /// (`None` for the terms of the exact evaluation at an irregular
    /// vertex itself, which the quadtree leaves out).
    pub fn visit_position_terms(
        &self,
        f: usize,
        st: [Real; 2],
        mut visit: impl FnMut(Option<usize>, u32, Real),
    ) {
        let patch = &self.patches[f];
        if patch.regular {
            let w = position_weights(st[0].clamp(0.0, 1.0), st[1].clamp(0.0, 1.0));
            let g = &self.grid_table;
            let first = g.offsets[16 * f];
            for (i, &wi) in w.iter().enumerate() {
                if wi != 0.0 {
                    for e in g.offsets[16 * f + i]..g.offsets[16 * f + i + 1] {
                        visit(Some(e - first), g.indices[e], wi * g.weights[e]);
                    }
                }
            }
            return;
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        let nc = tree.cols.len();
        if let Some((_, _, rows, x)) = tree.leaf_at(st) {
            let w = position_weights(x[0], x[1]);
            for (k, &c) in tree.cols.iter().enumerate() {
                visit(Some(k), c, (0..16).map(|i| w[i] * rows[i * nc + k]).sum());
            }
            return;
        }
        let s = evaluate_face(&self.level, &self.sharp, f, st[0], st[1]);
        for (&c, &w) in s.cols.iter().zip(&s.weights[0]) {
            visit(None, c, w);
        }
    }

    /// The refinement `P_L = S P_0` from the control points to level `L`.
    pub fn to_level(&self) -> &StencilTable {
        &self.to_level
    }

    /// For a patch at an irregular vertex: the level-`L` vertices its
    /// stencils use, in the order of its quadtree (the columns of
    /// [`stencils`](Self::stencils) wherever the quadtree answers), and the
    /// number of its local structure (topology, sharpness, face followed)
    /// in the table's [`QuadtreeCache`]. Patches with equal numbers have
    /// the same stencils at the same `(s, t)` up to that column order.
    /// `None` for a regular patch. Builds (and keeps) the quadtree.
    pub fn irregular_shape(&self, f: usize) -> Option<(&[u32], usize)> {
        let patch = &self.patches[f];
        if patch.regular {
            return None;
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        Some((&tree.cols, tree.shape.id))
    }

    /// The 16 bicubic B-spline control points of patch `f` as rows over the
    /// level-`L` vertices (phantom points at boundaries and creases are
    /// combinations), row `k` for weight `k` of
    /// [`patch_weights`](super::patch_weights); `None` for a patch at an
    /// irregular vertex.
    pub fn grid_rows(&self, f: usize) -> Option<[(&[u32], &[Real]); 16]> {
        self.patches[f]
            .regular
            .then(|| std::array::from_fn(|k| self.grid_table.row(16 * f + k)))
    }
}

/// Six row builders as one [`SampleStencil`] over the union of their columns.
fn builders_to_stencil(b: &[RowBuilder; 6]) -> SampleStencil {
    let mut cols: Vec<u32> = Vec::new();
    for (c, _) in b.iter().flat_map(|r| r.entries()) {
        if !cols.contains(&c) {
            cols.push(c);
        }
    }
    let weights = std::array::from_fn(|q| {
        let mut w = vec![0.0; cols.len()];
        for (c, x) in b[q].entries() {
            if let Some(k) = cols.iter().position(|&y| y == c) {
                w[k] += x;
            }
        }
        w
    });
    SampleStencil { cols, weights }
}

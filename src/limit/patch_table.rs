//! `PatchTable`: the limit surface of a fixed control mesh as bicubic patches.
//!
//! The control mesh is refined uniformly to level `L`; every level-`L` face
//! whose corners are regular becomes a bicubic B-spline patch with 16 control
//! points, which is exactly the limit surface over that face. A face that
//! touches an irregular vertex is, on first use, subdivided locally into a
//! quadtree of regular bicubic leaves [`TREE_DEPTH`] levels deep; only the
//! innermost cell at the irregular vertex is evaluated exactly, by further
//! local subdivision from the cell's own (cached) local patch, and the
//! vertex itself through [`LimitEvaluator`] (OpenSubdiv's feature-adaptive
//! patch tables rest on the same observation, Nießner et al. 2012).
//! Evaluation is then a 16-point product almost everywhere.
//!
//! Everything but the positions is built once: the patches' control points
//! are one stencil table over the level-`L` vertices, and the quadtree leaves
//! keep weights, not points. The weights depend on the face's one-ring
//! topology and sharpness alone, so faces whose one-rings have the same
//! local structure (in a cage, most faces at extraordinary vertices of one
//! valence) share one set. [`PatchTable::set_positions`] moves the control
//! mesh (as fitting does every step) with two sparse products.

use std::collections::HashMap;
use std::ops::{Add, Mul};
use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::stencil::{RowBuilder, StencilTable};
use crate::subdivision::{Hierarchy, Refiner};
use crate::topology::{Level, Sharpness};

use super::bspline::{cubic_basis, patch_weights, position_weights};
use super::patch::{
    CORNERS, CornerChain, LocalPatch, Ring, SampleStencil, child_frame, evaluate_face,
    evaluate_local, mat_mul, mat_vec, patch_grid, quadrant,
};
use super::vertex_masks::{CornerKind, corner_kind};
use super::{LimitEvaluator, LimitPoint, Sample};

/// Levels of local subdivision below `L` for faces at irregular vertices.
pub const TREE_DEPTH: usize = 6;

/// Rings of more columns than this (a vertex of valence above about 28)
/// evaluate their innermost cells through a [`CornerChain`]: exact
/// evaluation there otherwise subdivides the whole ring at every level,
/// for every point (O(levels × ring²) per point).
const CHAIN_COLUMNS: usize = 64;

/// A level-`L` face: its place in its base face and, near an irregular
/// vertex, its quadtree.
struct Patch {
    /// True when the face is a regular bicubic patch (rows in `grid_table`).
    regular: bool,
    /// Regular leaves of the local subdivision of an irregular face (lazy).
    tree: OnceLock<Tree>,
    base: u32,
    /// Base `(u, v) = origin + axes · (s, t)`.
    origin: [Real; 2],
    axes: [[Real; 2]; 2],
}

/// The quadtree of an irregular face: its leaves' control points are dense
/// rows of weights over the level-`L` vertices `cols` (the face's 1-ring).
struct Tree {
    cols: Vec<u32>,
    /// The leaves, shared by the faces of one structure.
    shape: Arc<Shape>,
    /// Each leaf at the current positions, made on first use (cleared by
    /// `set_positions`).
    points: Vec<OnceLock<LeafPoints>>,
}

/// A quadtree leaf at the current positions: a regular leaf's 16 control
/// points, or the innermost cell's local patch applied to the positions
/// ([`LocalPatch::applied`]) and followed towards its irregular vertex.
enum LeafPoints {
    Grid(Box<[Point3; 16]>),
    Cell(Box<CornerChain>),
}

impl Tree {
    /// The regular leaf holding `(s, t)`, its grid rows and the point in the
    /// leaf's own `(s', t')` (clamped to the unit square); `None` in the
    /// innermost cell at the irregular vertex.
    fn leaf_at(&self, st: [Real; 2]) -> Option<(usize, &Leaf, &[Real], [Real; 2])> {
        self.shape.leaves.iter().enumerate().find_map(|(i, leaf)| {
            let x = leaf.local(st)?;
            Some((i, leaf, &leaf.grid.as_ref()?[..], x))
        })
    }

    /// The innermost cell holding `(s, t)` (where [`leaf_at`](Self::leaf_at)
    /// finds none): its index, the leaf, its local patch and the point in
    /// its `(s', t')`.
    fn cell_at(&self, st: [Real; 2]) -> Option<(usize, &Leaf, &LocalPatch, [Real; 2])> {
        self.shape.leaves.iter().enumerate().find_map(|(i, leaf)| {
            let x = leaf.local(st)?;
            Some((i, leaf, &**leaf.cell.as_ref()?, x))
        })
    }
}

impl Leaf {
    /// `(s', t')` of the face's `(s, t)`, clamped to the unit square, if in
    /// this cell.
    fn local(&self, st: [Real; 2]) -> Option<[Real; 2]> {
        let x = [
            self.jac[0][0] * st[0] + self.jac[0][1] * st[1] + self.off[0],
            self.jac[1][0] * st[0] + self.jac[1][1] * st[1] + self.off[1],
        ];
        x.iter()
            .all(|c| (-1e-12..=1.0 + 1e-12).contains(c))
            .then(|| x.map(|c| c.clamp(0.0, 1.0)))
    }
}

/// A cell of an irregular face's quadtree: leaf `(s', t') = J (s, t) + c`
/// in the face's `(s, t)`, with its 16 bicubic control points as rows over
/// the tree's `cols`, one after the other (`None` for the innermost cell at an
/// irregular vertex, evaluated exactly from its local patch, `cell`).
struct Leaf {
    jac: [[Real; 2]; 2],
    off: [Real; 2],
    grid: Option<Vec<Real>>,
    cell: Option<Box<LocalPatch>>,
}

/// A bicubic piece's control points, the point in the piece's own
/// parameters and, for a quadtree leaf, their Jacobian.
type BicubicPiece<'a> = (&'a [Point3; 16], [Real; 2], Option<[[Real; 2]; 2]>);

/// Position and derivatives `∂s, ∂t, ∂ss, ∂st, ∂tt` in a patch's own `(s, t)`.
#[derive(Clone, Copy, Debug)]
pub struct PatchPoint {
    /// Position.
    pub p: Point3,
    /// `[Ps, Pt, Pss, Pst, Ptt]`.
    pub d: [Vector3; 5],
}

/// The limit surface of one control mesh (fixed positions) as level-`L` patches.
pub struct PatchTable {
    evaluator: LimitEvaluator,
    level: Level,
    sharp: Sharpness,
    /// Level-0 → level-`L` refinement, `P_L = S P_0`.
    to_level: StencilTable,
    /// Control points of the regular patches: rows `16 f .. 16 f + 16` over
    /// level-`L` vertices (empty rows for irregular faces).
    grid_table: StencilTable,
    positions: Vec<Point3>,
    level_positions: Vec<Point3>,
    grid_points: Vec<Point3>,
    /// Face offsets of levels `0..L`, to locate a base `(face, u, v)`.
    offsets: Vec<Vec<u32>>,
    patches: Vec<Patch>,
    /// Quadtree leaves by local structure (see [`QuadtreeCache`]).
    shapes: QuadtreeCache,
}

impl Drop for PatchTable {
    /// Frees the patches (their quadtrees and cached points: many small
    /// allocations) on the thread pool rather than the caller's thread,
    /// which would otherwise stall on them between fitting levels.
    fn drop(&mut self) {
        let patches = std::mem::take(&mut self.patches);
        if patches.len() >= 4096 {
            rayon::spawn(move || drop(patches));
        }
    }
}

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
type Shapes = HashMap<Vec<u64>, Arc<Shape>>;

/// The quadtree leaves of one local structure and the structure's number
/// in its [`QuadtreeCache`] (the order it was first met in).
struct Shape {
    id: usize,
    leaves: Vec<Leaf>,
}

impl std::fmt::Debug for QuadtreeCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.0.lock().map_or(0, |s| s.len());
        write!(f, "QuadtreeCache({n} structures)")
    }
}

impl PatchTable {
    /// Refines to `level` (1 to 6) and builds the regular patches.
    pub fn new(refiner: &Refiner, positions: &[Point3], level: usize) -> Result<PatchTable> {
        Self::with_quadtrees(refiner, positions, level, QuadtreeCache::default())
    }

    /// [`new`](Self::new) with quadtrees looked up in and added to `shapes`.
    pub fn with_quadtrees(
        refiner: &Refiner,
        positions: &[Point3],
        level: usize,
        shapes: QuadtreeCache,
    ) -> Result<PatchTable> {
        if level == 0 || level > 6 {
            return Err(Error::Input(format!(
                "patch level {level} must be between 1 and 6"
            )));
        }
        if positions.len() != refiner.level.num_vertices {
            return Err(Error::Input(format!(
                "{} positions for a mesh of {} vertices",
                positions.len(),
                refiner.level.num_vertices
            )));
        }
        super::evaluator::check_ring_sizes(&refiner.level)?;
        let h = refiner.refine_uniform(level)?;
        let fine = h.finest();
        let sharp = h.sharpness.last().expect("levels exist");
        let maps = param_maps(&h);
        // A smooth corner is smooth in every face around its vertex (the
        // kind then depends on the vertex alone): each vertex is classified
        // once, and only the other corners face by face.
        let smooth: Vec<bool> = (0..fine.num_vertices)
            .into_par_iter()
            .map(|v| {
                fine.vertex_faces(v)
                    .first()
                    .is_some_and(|&f| corner_kind(fine, sharp, v, f) == CornerKind::Smooth)
            })
            .collect();
        let regular: Vec<bool> = (0..fine.num_faces())
            .into_par_iter()
            .map(|f| {
                fine.face_vertices(f).iter().all(|&c| {
                    smooth[c as usize]
                        || corner_kind(fine, sharp, c as usize, f as u32) != CornerKind::Irregular
                })
            })
            .collect();
        // Each face's 16 rows (empty at an irregular face): their ends,
        // columns and weights, made in parallel and then laid end to end.
        let grids: Vec<([usize; 16], Vec<u32>, Vec<Real>)> = (0..fine.num_faces())
            .into_par_iter()
            .map(|f| {
                let (mut ends, mut cols, mut weights) = ([0; 16], Vec::new(), Vec::new());
                if regular[f] {
                    for (end, row) in ends.iter_mut().zip(patch_grid(fine, sharp, f)) {
                        for (c, w) in row.entries() {
                            cols.push(c);
                            weights.push(w);
                        }
                        *end = cols.len();
                    }
                }
                (ends, cols, weights)
            })
            .collect();
        let mut grid_table = StencilTable::with_capacity(
            fine.num_vertices,
            16 * grids.len(),
            grids.iter().map(|g| g.1.len()).sum(),
        );
        for (ends, cols, weights) in grids {
            let first = grid_table.indices.len();
            grid_table.offsets.extend(ends.map(|e| first + e));
            grid_table.indices.extend(cols);
            grid_table.weights.extend(weights);
        }
        let patches = maps
            .into_iter()
            .zip(&regular)
            .map(|((base, origin, axes), &regular)| Patch {
                regular,
                tree: OnceLock::new(),
                base,
                origin,
                axes,
            })
            .collect();
        let mut table = PatchTable {
            evaluator: LimitEvaluator::new(refiner),
            level: fine.clone(),
            sharp: sharp.clone(),
            to_level: h.stencil_to_level(level)?,
            grid_table,
            positions: Vec::new(),
            level_positions: Vec::new(),
            grid_points: Vec::new(),
            offsets: h.levels[..level]
                .iter()
                .map(|l| l.face_offsets.clone())
                .collect(),
            patches,
            shapes,
        };
        table.set_positions(positions)?;
        Ok(table)
    }

    /// Moves the control points (same topology): two sparse products; the
    /// quadtrees built so far are kept.
    pub fn set_positions(&mut self, positions: &[Point3]) -> Result<()> {
        crate::mesh::check_finite(positions)?;
        if positions.len() != self.to_level.num_cols {
            return Err(Error::Input(format!(
                "{} control points for a patch table over {}",
                positions.len(),
                self.to_level.num_cols
            )));
        }
        // Into the buffers already there (sized on the first call): fresh
        // ones would be zeroed and faulted in on one thread.
        self.level_positions
            .resize(self.to_level.num_rows(), Point3::origin());
        self.grid_points
            .resize(self.grid_table.num_rows(), Point3::origin());
        self.to_level
            .apply_into(positions, &mut self.level_positions);
        self.grid_table
            .apply_into(&self.level_positions, &mut self.grid_points);
        self.patches.par_iter_mut().for_each(|patch| {
            if let Some(tree) = patch.tree.get_mut() {
                for points in &mut tree.points {
                    points.take();
                }
            }
        });
        self.positions.clear();
        self.positions.extend_from_slice(positions);
        Ok(())
    }

    /// The control points.
    pub fn positions(&self) -> &[Point3] {
        &self.positions
    }

    /// Number of patches (faces of level `L`).
    pub fn num_patches(&self) -> usize {
        self.patches.len()
    }

    /// Number of faces of the base (control) mesh.
    pub fn num_base_faces(&self) -> usize {
        self.offsets
            .first()
            .map_or(self.patches.len(), |o| o.len() - 1)
    }

    /// The base face that patch `f` is a piece of.
    pub fn base_face(&self, f: usize) -> usize {
        self.patches[f].base as usize
    }

    /// Connectivity of level `L` (patch `f` is face `f`).
    pub fn level(&self) -> &Level {
        &self.level
    }

    /// Evaluates patch `f` at `(s, t) ∈ [0, 1]²`.
    pub fn eval(&self, f: usize, st: [Real; 2]) -> Result<PatchPoint> {
        if let Some((grid, x, jac)) = self.bicubic_piece(f, st) {
            let e = bicubic(grid, x);
            return Ok(PatchPoint {
                p: e.p,
                d: jac.map_or(e.d, |j| chain(e.d, j)),
            });
        }
        let patch = &self.patches[f];
        // The innermost cell at the irregular vertex: exact evaluation from
        // the cell's local patch (its weights are over the tree's columns,
        // in order), followed towards the vertex once per positions when
        // its ring is large. Exactly at a corner the evaluator's corner
        // tangents (which depend on the depth they are taken at) are kept.
        if let Some(tree) = patch.tree.get()
            && let Some((i, leaf, cell, x)) = tree.cell_at(st)
            && !CORNERS.contains(&x)
        {
            let q: [Vector3; 6] = if tree.cols.len() > CHAIN_COLUMNS
                && let LeafPoints::Cell(corner) = tree.points[i].get_or_init(|| {
                    let cell = cell.applied(|l| self.level_positions[tree.cols[l] as usize].coords);
                    LeafPoints::Cell(Box::new(CornerChain::new(cell, TREE_DEPTH)))
                }) {
                let s = corner.evaluate(x);
                std::array::from_fn(|k| Vector3::from_column_slice(&s.weights[k]))
            } else {
                let s = evaluate_local(cell.clone(), x, [[1.0, 0.0], [0.0, 1.0]], TREE_DEPTH);
                std::array::from_fn(|k| {
                    s.weights[k]
                        .iter()
                        .zip(&tree.cols)
                        .map(|(&w, &c)| w * self.level_positions[c as usize].coords)
                        .sum()
                })
            };
            return Ok(PatchPoint {
                p: Point3::from(q[0]),
                d: chain([q[1], q[2], q[3], q[4], q[5]], leaf.jac),
            });
        }
        let s = self.sample(f, st);
        let e = self
            .evaluator
            .evaluate(s.face as usize, s.u, s.v, &self.positions)?;
        Ok(PatchPoint {
            p: e.p,
            d: chain([e.du, e.dv, e.duu, e.duv, e.dvv], patch.axes),
        })
    }

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

    /// The affine map of patch `f`'s `(s, t)` into its base face's `(u, v)`:
    /// `(u, v) = origin + axes · (s, t)`.
    pub fn patch_frame(&self, f: usize) -> ([Real; 2], [[Real; 2]; 2]) {
        (self.patches[f].origin, self.patches[f].axes)
    }

    /// The cells on which patch `f` is one polynomial piece: `(J, c)` with
    /// cell coordinates `J (s, t) + c ∈ [0, 1]²` — the whole patch for a
    /// regular face, the quadtree leaves (and the innermost cells) otherwise.
    /// Quadrature on each cell is exact for polynomial integrands.
    pub fn cells(&self, f: usize) -> Vec<([[Real; 2]; 2], [Real; 2])> {
        let patch = &self.patches[f];
        if patch.regular {
            return vec![([[1.0, 0.0], [0.0, 1.0]], [0.0, 0.0])];
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        tree.shape.leaves.iter().map(|l| (l.jac, l.off)).collect()
    }

    /// The base-face sample of patch `f` at `(s, t)`.
    pub fn sample(&self, f: usize, st: [Real; 2]) -> Sample {
        let p = &self.patches[f];
        let a = p.axes;
        Sample {
            face: p.base,
            u: p.origin[0] + a[0][0] * st[0] + a[0][1] * st[1],
            v: p.origin[1] + a[1][0] * st[0] + a[1][1] * st[1],
        }
    }

    /// Sign of the orientation of patch `f`'s `(s, t)` relative to its base
    /// face's `(u, v)` (rotations keep it at +1).
    pub fn orientation(&self, f: usize) -> Real {
        let a = self.patches[f].axes;
        (a[0][0] * a[1][1] - a[0][1] * a[1][0]).signum()
    }

    /// The patch and `(s, t)` holding base sample `(face, u, v)`; ties go to
    /// the upper half as in the evaluator.
    pub fn locate(&self, face: usize, u: Real, v: Real) -> (usize, [Real; 2]) {
        let mut f = face;
        let mut st = [u, v];
        for (k, offs) in self.offsets.iter().enumerate() {
            let n = (offs[f + 1] - offs[f]) as usize;
            let i = if k == 0 && n != 4 {
                let (i, sub) = super::patch::subface(n, u, v);
                st = sub;
                i
            } else {
                let q = quadrant(st);
                st = child_frame(q, st).0;
                q
            };
            f = offs[f] as usize + i;
        }
        (f, st)
    }

    /// Limit position and derivatives at base sample `(face, u, v)`.
    pub fn evaluate(&self, face: usize, u: Real, v: Real) -> Result<LimitPoint> {
        if face + 1 >= self.offsets[0].len() {
            return Err(Error::Input(format!("face {face} out of range")));
        }
        let (f, st) = self.locate(face, u, v);
        let e = self.eval(f, st)?;
        // (s, t) = A⁻¹ ((u, v) − o): invert the patch axes for the chain rule.
        let a = self.patches[f].axes;
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let d = chain(e.d, inv);
        Ok(LimitPoint {
            p: e.p,
            du: d[0],
            dv: d[1],
            duu: d[2],
            duv: d[3],
            dvv: d[4],
        })
    }

    /// The limit point of patch `f` at `(s, t)`: [`eval`](Self::eval)'s
    /// position without the derivatives (a quarter of the work on a
    /// bicubic piece).
    pub fn position(&self, f: usize, st: [Real; 2]) -> Result<Point3> {
        match self.bicubic_piece(f, st) {
            Some((grid, x, _)) => {
                let (bs, bt) = (cubic_basis(x[0])[0], cubic_basis(x[1])[0]);
                let mut p = [0.0; 3];
                for (row, ws) in grid.chunks_exact(4).zip(bs) {
                    for (x, p) in p.iter_mut().enumerate() {
                        *p += ws
                            * (bt[0] * row[0][x]
                                + bt[1] * row[1][x]
                                + bt[2] * row[2][x]
                                + bt[3] * row[3][x]);
                    }
                }
                Ok(Point3::from(p))
            }
            None => Ok(self.eval(f, st)?.p),
        }
    }

    /// The bicubic piece of patch `f` holding `(s, t)`: its 16 control points,
    /// the point in its own parameters and, for a quadtree leaf, the
    /// Jacobian of those; `None` in the innermost cell at an irregular
    /// vertex.
    fn bicubic_piece(&self, f: usize, st: [Real; 2]) -> Option<BicubicPiece<'_>> {
        let patch = &self.patches[f];
        if patch.regular {
            let grid: &[Point3; 16] = self.grid_points[16 * f..16 * f + 16]
                .try_into()
                .expect("16 control points per patch");
            return Some((grid, st, None));
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        let (i, leaf, rows, x) = tree.leaf_at(st)?;
        let cols = &tree.cols;
        let nc = cols.len().max(1);
        let points = tree.points[i].get_or_init(|| {
            LeafPoints::Grid(Box::new(std::array::from_fn(|k| {
                let mut p = [0.0; 3];
                for (&w, &c) in rows[k * nc..(k + 1) * nc].iter().zip(cols) {
                    let q = &self.level_positions[c as usize];
                    p[0] += w * q.x;
                    p[1] += w * q.y;
                    p[2] += w * q.z;
                }
                Point3::from(p)
            })))
        });
        let LeafPoints::Grid(grid) = points else {
            return None;
        };
        Some((grid, x, Some(leaf.jac)))
    }

    /// The quadtree of irregular level-`L` face `f` (see module docs).
    /// The local patch is built only for a structure not met before; the
    /// first structure stored under a key is the one every tree shares.
    fn tree(&self, f: usize) -> Tree {
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

/// Bicubic B-spline patch value and derivatives at `(s, t)`.
fn bicubic(grid: &[Point3; 16], st: [Real; 2]) -> PatchPoint {
    // The weights of `patch_weights`, as a tensor product: first along `t`
    // (`c[k][a]`, derivative order `k` in `t`), then along `s`. Written out
    // on plain coordinates: this is the inner loop of every closest-point
    // descent.
    let (bs, bt) = (cubic_basis(st[0]), cubic_basis(st[1]));
    let mut c = [[[0.0; 3]; 4]; 3];
    for (a, row) in grid.chunks_exact(4).enumerate() {
        for (k, w) in bt.iter().enumerate() {
            for x in 0..3 {
                c[k][a][x] =
                    w[0] * row[0][x] + w[1] * row[1][x] + w[2] * row[2][x] + w[3] * row[3][x];
            }
        }
    }
    let along = |ds: usize, dt: usize| -> Vector3 {
        let (w, c) = (&bs[ds], &c[dt]);
        Vector3::from_fn(|x, _| w[0] * c[0][x] + w[1] * c[1][x] + w[2] * c[2][x] + w[3] * c[3][x])
    };
    PatchPoint {
        p: Point3::from(along(0, 0)),
        d: [
            along(1, 0),
            along(0, 1),
            along(2, 0),
            along(1, 1),
            along(0, 2),
        ],
    }
}

/// Chain rule for `(s', t') = J (s, t) + c`: maps `[Ps', Pt', Ps's', Ps't', Pt't']`
/// to `[Ps, Pt, Pss, Pst, Ptt]`.
pub(crate) fn chain<T>(d: [T; 5], j: [[Real; 2]; 2]) -> [T; 5]
where
    T: Copy + Mul<Real, Output = T> + Add<Output = T>,
{
    let (su, sv, tu, tv) = (j[0][0], j[0][1], j[1][0], j[1][1]);
    [
        d[0] * su + d[1] * tu,
        d[0] * sv + d[1] * tv,
        d[2] * (su * su) + d[3] * (2.0 * su * tu) + d[4] * (tu * tu),
        d[2] * (su * sv) + d[3] * (su * tv + sv * tu) + d[4] * (tu * tv),
        d[2] * (sv * sv) + d[3] * (2.0 * sv * tv) + d[4] * (tv * tv),
    ]
}

/// For every face of the finest level: its base face and the affine map from
/// its `(s, t)` to the base face's `(u, v)`.
fn param_maps(h: &Hierarchy) -> Vec<(u32, [Real; 2], [[Real; 2]; 2])> {
    let l0 = h.level(0);
    let mut maps: Vec<(u32, [Real; 2], [[Real; 2]; 2])> = (0..l0.num_faces() as u32)
        .map(|f| (f, [0.0, 0.0], [[1.0, 0.0], [0.0, 1.0]]))
        .collect();
    for k in 0..h.num_levels() {
        let parent = h.level(k);
        let mut next = Vec::with_capacity(parent.face_verts.len());
        for (f, &(base, o, a)) in maps.iter().enumerate() {
            let n = parent.face_vertices(f).len();
            for i in 0..n {
                if n != 4 {
                    // n-gon sub-face i: its tile, at half scale (only at level 0).
                    let d = (n as Real).sqrt().ceil() as usize;
                    next.push((
                        base,
                        [(i % d) as Real, (i / d) as Real],
                        [[0.5, 0.0], [0.0, 0.5]],
                    ));
                    continue;
                }
                // Child i: corner 0 at parent corner i, s towards i+1, t towards i−1.
                let c = CORNERS[i];
                let ax = [
                    CORNERS[(i + 1) % 4][0] - c[0],
                    CORNERS[(i + 1) % 4][1] - c[1],
                ];
                let bx = [
                    CORNERS[(i + 3) % 4][0] - c[0],
                    CORNERS[(i + 3) % 4][1] - c[1],
                ];
                // parent (s, t) = c + ½ (ax s' + bx t'); base = o + a · parent.
                let po = [
                    o[0] + a[0][0] * c[0] + a[0][1] * c[1],
                    o[1] + a[1][0] * c[0] + a[1][1] * c[1],
                ];
                let col = |v: [Real; 2]| {
                    [
                        0.5 * (a[0][0] * v[0] + a[0][1] * v[1]),
                        0.5 * (a[1][0] * v[0] + a[1][1] * v[1]),
                    ]
                };
                let (cs, ct) = (col(ax), col(bx));
                next.push((base, po, [[cs[0], ct[0]], [cs[1], ct[1]]]));
            }
        }
        maps = next;
    }
    maps
}

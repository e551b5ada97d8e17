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

mod build;
mod cache;
mod eval;
mod map;
mod stencils;

pub use cache::QuadtreeCache;
use cache::Shape;

use std::sync::{Arc, OnceLock};

use crate::math::{Point3, Real, Vector3};
use crate::stencil::StencilTable;
use crate::topology::{Level, Sharpness};

use crate::limit::LimitEvaluator;
use crate::limit::local_eval::CornerChain;
use crate::limit::patch::LocalPatch;

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

impl PatchTable {
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
}

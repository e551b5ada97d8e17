//! `Refiner`: level-0 topology and tags, and uniform refinement into a
//! [`Hierarchy`] of levels with their stencil tables.

use std::str::FromStr;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;
use crate::topology::{Level, Sharpness};

use super::{refine_stencil, refine_topology};

/// How boundary vertices are treated (OpenSubdiv's `VtxBoundaryInterpolation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryRule {
    /// Boundary edges are sharp and boundary vertices with a single face
    /// (valence 2) are corners that stay put. The default.
    #[default]
    EdgeAndCorner,
    /// Boundary edges are sharp; valence-2 boundary vertices follow the
    /// boundary curve rule like any other boundary vertex.
    EdgeOnly,
}

impl FromStr for BoundaryRule {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "edge-and-corner" => Ok(BoundaryRule::EdgeAndCorner),
            "edge-only" => Ok(BoundaryRule::EdgeOnly),
            _ => Err(Error::Input(format!(
                "unknown boundary rule '{s}': expected edge-and-corner or edge-only"
            ))),
        }
    }
}

/// Options of [`Refiner::new`].
#[derive(Clone, Debug, Default)]
pub struct RefineOptions {
    /// Boundary rule; default [`BoundaryRule::EdgeAndCorner`].
    pub boundary: BoundaryRule,
    /// Creases `(i, j, s)`: the edge joining vertices `i` and `j` gets
    /// sharpness `s` (≥ 10 is infinite). Default: none.
    pub creases: Vec<(u32, u32, Real)>,
}

/// Level-0 topology with its sharpness tags, ready to refine.
///
/// ```
/// use subdyn::subdivision::{Refiner, RefineOptions};
/// let cube = subdyn::examples::cube();
/// let r = Refiner::new(&cube, &RefineOptions::default()).unwrap();
/// let h = r.refine_uniform(1).unwrap();
/// assert_eq!(h.level(1).num_faces(), 24);
/// // every stencil row is an affine combination
/// assert!(h.stencil(0).row_sums().iter().all(|s| (s - 1.0).abs() < 1e-12));
/// ```
#[derive(Clone, Debug)]
pub struct Refiner {
    /// Level-0 connectivity.
    pub level: Level,
    /// Level-0 sharpness.
    pub sharpness: Sharpness,
    /// The options it was built with.
    pub options: RefineOptions,
}

/// Levels `0..=n` of a uniform refinement and the stencils between them.
#[derive(Clone, Debug)]
pub struct Hierarchy {
    /// `levels[k]` is the connectivity of level `k`.
    pub levels: Vec<Level>,
    /// `sharpness[k]` are the tags of level `k`.
    pub sharpness: Vec<Sharpness>,
    /// `stencils[k]` maps level `k` to level `k + 1`.
    pub stencils: Vec<StencilTable>,
}

impl Refiner {
    /// Builds and checks level-0 topology and tags.
    pub fn new(mesh: &PolyMesh, options: &RefineOptions) -> Result<Refiner> {
        let level = Level::from_mesh(mesh)?;
        let sharpness = Sharpness::initial(
            &level,
            &options.creases,
            options.boundary == BoundaryRule::EdgeAndCorner,
        )?;
        Ok(Refiner {
            level,
            sharpness,
            options: options.clone(),
        })
    }

    /// Refines uniformly `levels` times.
    pub fn refine_uniform(&self, levels: usize) -> Result<Hierarchy> {
        if levels > 12 {
            return Err(Error::Input(format!(
                "{levels} levels requested; uniform refinement multiplies faces by 4 per level, \
                 so more than 12 levels is refused"
            )));
        }
        let mut h = Hierarchy {
            levels: vec![self.level.clone()],
            sharpness: vec![self.sharpness.clone()],
            stencils: Vec::with_capacity(levels),
        };
        for _ in 0..levels {
            h.push_level();
        }
        Ok(h)
    }
}

impl Hierarchy {
    /// Refines the finest level once more.
    pub fn push_level(&mut self) {
        let (parent, sharp) = (self.finest(), self.sharpness.last().expect("level 0"));
        let child = refine_topology(parent);
        let (s, child_sharp) = refine_stencil(parent, sharp, &child);
        self.levels.push(child);
        self.sharpness.push(child_sharp);
        self.stencils.push(s);
    }

    /// Index of the finest level.
    pub fn num_levels(&self) -> usize {
        self.levels.len() - 1
    }

    /// Connectivity of level `k`.
    pub fn level(&self, k: usize) -> &Level {
        &self.levels[k]
    }

    /// The finest level.
    pub fn finest(&self) -> &Level {
        self.levels.last().expect("a hierarchy has level 0")
    }

    /// The stencil from level `k` to `k + 1`.
    pub fn stencil(&self, k: usize) -> &StencilTable {
        &self.stencils[k]
    }

    /// The composed table `S = S_{n−1} ⋯ S_0` with `P_n = S P_0`.
    pub fn stencil_to_level(&self, n: usize) -> Result<StencilTable> {
        if n > self.num_levels() {
            return Err(Error::Input(format!(
                "level {n} requested but the hierarchy has {} levels",
                self.num_levels()
            )));
        }
        let mut s = StencilTable::identity(self.levels[0].num_vertices);
        for k in 0..n {
            s = self.stencils[k].compose(&s)?;
        }
        Ok(s)
    }

    /// Positions of every level, refining level by level from `p0`.
    pub fn refine_positions(
        &self,
        p0: &[crate::math::Point3],
    ) -> Result<Vec<Vec<crate::math::Point3>>> {
        let mut out = vec![p0.to_vec()];
        for s in &self.stencils {
            let next = s.apply(out.last().expect("level 0"))?;
            out.push(next);
        }
        Ok(out)
    }

    /// The finest level as a mesh with the given positions.
    pub fn mesh(&self, k: usize, positions: Vec<crate::math::Point3>) -> PolyMesh {
        let l = &self.levels[k];
        PolyMesh {
            positions,
            face_offsets: l.face_offsets.clone(),
            face_vertices: l.face_verts.clone(),
        }
    }
}

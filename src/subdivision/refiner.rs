//! `Refiner`: level-0 topology and tags, and uniform refinement into a
//! [`Hierarchy`] of levels with their stencil tables.

use std::str::FromStr;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;
use crate::topology::{CreaseMethod, Level, SHARPNESS_INFINITE, Sharpness};

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
    /// No surface along the boundary: the faces around every boundary vertex
    /// become holes, except where the vertex's boundary edges were tagged
    /// infinitely sharp (OpenSubdiv's `VTX_BOUNDARY_NONE`; the points are
    /// those of [`BoundaryRule::EdgeOnly`]).
    None,
}

/// The edge-point rule next to triangles (OpenSubdiv's `TriangleSubdivision`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TriangleRule {
    /// Catmull and Clark's rule for every face. The default.
    #[default]
    Catmark,
    /// Edges of a triangle weight its face point 0.47 instead of ¼
    /// (OpenSubdiv's `TRI_SUB_SMOOTH`, its option for smoother surfaces over triangles).
    Smooth,
}

impl FromStr for TriangleRule {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "catmark" => Ok(TriangleRule::Catmark),
            "smooth" => Ok(TriangleRule::Smooth),
            _ => Err(Error::input(format!(
                "unknown triangle rule '{s}': expected catmark or smooth"
            ))),
        }
    }
}

impl BoundaryRule {
    /// The command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            BoundaryRule::EdgeAndCorner => "edge-and-corner",
            BoundaryRule::EdgeOnly => "edge-only",
            BoundaryRule::None => "none",
        }
    }
}

impl FromStr for BoundaryRule {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "edge-and-corner" => Ok(BoundaryRule::EdgeAndCorner),
            "edge-only" => Ok(BoundaryRule::EdgeOnly),
            "none" => Ok(BoundaryRule::None),
            _ => Err(Error::input(format!(
                "unknown boundary rule '{s}': expected edge-and-corner, edge-only or none"
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
    /// Vertex sharpness `(v, s)`: vertex `v` is a corner while `s` lasts
    /// (decaying by 1 per level; ≥ 10 is infinite). Default: none.
    pub corners: Vec<(u32, Real)>,
    /// Faces that are holes: refined and used by their neighbours' rules,
    /// but not part of the surface (left out of refined meshes and limit
    /// tessellations). Default: none.
    pub holes: Vec<u32>,
    /// How semi-sharp creases decay; default uniform.
    pub crease_method: CreaseMethod,
    /// The edge rule next to triangles; default Catmull-Clark's.
    pub triangles: TriangleRule,
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
    /// Level-0 hole faces (empty when there are none).
    pub holes: Vec<bool>,
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
    /// `holes[k]` marks the hole faces of level `k` (empty: none).
    pub holes: Vec<Vec<bool>>,
    /// The edge rule next to triangles.
    pub triangles: TriangleRule,
}

impl Refiner {
    /// Builds and checks level-0 topology and tags.
    pub fn new(mesh: &PolyMesh, options: &RefineOptions) -> Result<Refiner> {
        let level = Level::from_mesh(mesh)?;
        let sharpness = Sharpness::initial(
            &level,
            &options.creases,
            &options.corners,
            options.boundary == BoundaryRule::EdgeAndCorner,
            options.crease_method,
        )?;
        let mut holes = vec![false; level.num_faces()];
        for (k, &f) in options.holes.iter().enumerate() {
            *holes.get_mut(f as usize).ok_or_else(|| {
                Error::out_of_range(format!(
                    "hole {k}: face {f} is not in the mesh ({} faces)",
                    level.num_faces()
                ))
            })? = true;
        }
        if options.boundary == BoundaryRule::None {
            boundary_holes(&level, &options.creases, &mut holes);
        }
        if !holes.contains(&true) {
            holes.clear();
        }
        Ok(Refiner {
            level,
            sharpness,
            holes,
            options: options.clone(),
        })
    }

    /// Refines uniformly `levels` times.
    pub fn refine_uniform(&self, levels: usize) -> Result<Hierarchy> {
        if levels > 12 {
            return Err(Error::input(format!(
                "{levels} levels requested; uniform refinement multiplies faces by 4 per level, \
                 so more than 12 levels is refused"
            )));
        }
        let mut h = Hierarchy {
            levels: vec![self.level.clone()],
            sharpness: vec![self.sharpness.clone()],
            stencils: Vec::with_capacity(levels),
            holes: vec![self.holes.clone()],
            triangles: self.options.triangles,
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
        let smooth = self.triangles == TriangleRule::Smooth;
        let (s, child_sharp) = refine_stencil(parent, sharp, &child, smooth);
        // Child face c is the child of parent corner c.
        let holes = self.holes.last().expect("level 0");
        let child_holes = if holes.is_empty() {
            Vec::new()
        } else {
            (0..parent.num_faces())
                .flat_map(|f| std::iter::repeat_n(holes[f], parent.face_vertices(f).len()))
                .collect()
        };
        self.levels.push(child);
        self.sharpness.push(child_sharp);
        self.stencils.push(s);
        self.holes.push(child_holes);
    }

    /// Whether face `f` of level `k` is a hole.
    pub fn is_hole(&self, k: usize, f: usize) -> bool {
        self.holes[k].get(f).copied().unwrap_or(false)
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
            return Err(Error::input(format!(
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

    /// Level `k` as a mesh with the given positions, its hole faces left out.
    pub fn mesh(&self, k: usize, positions: Vec<crate::math::Point3>) -> PolyMesh {
        let l = &self.levels[k];
        if self.holes[k].is_empty() {
            return PolyMesh {
                positions,
                face_offsets: l.face_offsets.clone(),
                face_vertices: l.face_verts.clone(),
            };
        }
        let mut face_offsets = vec![0];
        let mut face_vertices = Vec::new();
        for f in (0..l.num_faces()).filter(|&f| !self.holes[k][f]) {
            face_vertices.extend_from_slice(l.face_vertices(f));
            face_offsets.push(face_vertices.len() as u32);
        }
        PolyMesh {
            positions,
            face_offsets,
            face_vertices,
        }
    }
}

/// Marks as holes the faces around each boundary vertex with a boundary edge
/// the user did not tag infinitely sharp (OpenSubdiv 3.6, `Far::
/// TopologyRefinerFactoryBase::prepareComponentTagsAndSharpness` for
/// `VTX_BOUNDARY_NONE`).
fn boundary_holes(level: &Level, creases: &[(u32, u32, Real)], holes: &mut [bool]) {
    let tagged: std::collections::HashSet<usize> = creases
        .iter()
        .filter(|c| c.2 as f32 as Real >= SHARPNESS_INFINITE)
        .filter_map(|&(i, j, _)| crate::topology::find_edge(level, i, j))
        .collect();
    for v in 0..level.num_vertices {
        let open = level
            .vertex_edges(v)
            .iter()
            .any(|&e| level.is_boundary_edge(e as usize) && !tagged.contains(&(e as usize)));
        if open {
            for &f in level.vertex_faces(v) {
                holes[f as usize] = true;
            }
        }
    }
}

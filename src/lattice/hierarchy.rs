//! `LatticeHierarchy`: a lattice's topology refined `n` times with a stencil
//! table per level and the composed `S_n` (MacCracken & Joy 1996, §6: the
//! subdivision steps run once, when the lattice is frozen; deforming only
//! re-applies the rules).

use crate::error::{Error, Result};
use crate::math::Point3;
use crate::stencil::StencilTable;

use super::lattice::{BoundaryTags, Lattice};
use super::refine_topology::{TypeNCells, refined_topology};
use super::rules::{refined_tags, refinement_stencil};
use super::topology::LatticeTopology;

/// Most refinement levels accepted (cells grow about eightfold per level).
pub const MAX_LATTICE_LEVELS: usize = 6;

/// One level of a refined lattice.
#[derive(Clone, Debug)]
pub struct LatticeLevel {
    /// Vertices, edges, faces, cells.
    pub topology: LatticeTopology,
    /// Corners and sharp edges at this level.
    pub tags: BoundaryTags,
    /// Every cell as a type-n cell (`None` at level 0, whose cells are arbitrary polyhedra).
    pub type_n: Option<TypeNCells>,
}

/// Levels `0..=n` of a refined lattice and the stencils between them.
#[derive(Clone, Debug)]
pub struct LatticeHierarchy {
    /// `levels[k]` is level `k`; level 0 is the input lattice.
    pub levels: Vec<LatticeLevel>,
    /// `stencils[k]` maps level `k` to level `k + 1`.
    pub stencils: Vec<StencilTable>,
}

impl LatticeHierarchy {
    /// Refines the lattice's topology `n` times (at most [`MAX_LATTICE_LEVELS`]).
    pub fn new(lattice: &Lattice, n: usize) -> Result<LatticeHierarchy> {
        Self::from_topology(&lattice.topology, &lattice.tags, n)
    }

    /// Refines a topology with its tags `n` times.
    pub fn from_topology(
        topo: &LatticeTopology,
        tags: &BoundaryTags,
        n: usize,
    ) -> Result<LatticeHierarchy> {
        if n > MAX_LATTICE_LEVELS {
            return Err(Error::input(format!(
                "{n} lattice levels requested; at most {MAX_LATTICE_LEVELS} are allowed (cells grow eightfold per level)"
            )));
        }
        tags.check(topo)?;
        let mut levels = vec![LatticeLevel {
            topology: topo.clone(),
            tags: tags.clone(),
            type_n: None,
        }];
        let mut stencils = Vec::with_capacity(n);
        for _ in 0..n {
            let last = levels.last().ok_or_else(|| Error::input("no level"))?;
            let s = refinement_stencil(&last.topology, &last.tags);
            let (child, type_n) = refined_topology(&last.topology)?;
            let child_tags = refined_tags(&last.topology, &last.tags, &child);
            stencils.push(s);
            levels.push(LatticeLevel {
                topology: child,
                tags: child_tags,
                type_n: Some(type_n),
            });
        }
        Ok(LatticeHierarchy { levels, stencils })
    }

    /// Number of refinement levels `n`.
    pub fn depth(&self) -> usize {
        self.stencils.len()
    }

    /// Level `k`.
    pub fn level(&self, k: usize) -> &LatticeLevel {
        &self.levels[k]
    }

    /// The composed table `S_k = S_{k-1} ⋯ S_0` from level-0 control points to level `k`.
    pub fn stencil_to_level(&self, k: usize) -> Result<StencilTable> {
        if k > self.depth() {
            return Err(Error::input(format!(
                "level {k} requested from a lattice refined {} times",
                self.depth()
            )));
        }
        let Some((first, rest)) = self.stencils[..k].split_first() else {
            return Ok(StencilTable::identity(self.levels[0].topology.num_vertices));
        };
        let mut s = first.clone();
        for t in rest {
            s = t.compose(&s)?;
        }
        Ok(s)
    }

    /// Positions of every level, level by level from the level-0 control points.
    pub fn refine_positions(&self, p0: &[Point3]) -> Result<Vec<Vec<Point3>>> {
        let mut out = vec![p0.to_vec()];
        for s in &self.stencils {
            let next = s.apply(out.last().map(Vec::as_slice).unwrap_or(&[]))?;
            out.push(next);
        }
        Ok(out)
    }

    /// Bytes held by the topology (and type-n cells) of level `k`.
    pub fn topology_bytes(&self, k: usize) -> usize {
        let l = &self.levels[k];
        l.topology.bytes()
            + l.type_n.as_ref().map_or(0, TypeNCells::bytes)
            + l.tags.corners.len()
            + l.tags.sharp_edges.len()
    }
}

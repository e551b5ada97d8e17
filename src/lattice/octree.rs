//! Octree subdivision of a whole lattice (multiresolution-lattice FFD paper,
//! §2.1): a cell point (average of the cell's control points), a face point
//! (average of the face's), an edge point (the midpoint) for every cell, face
//! and edge; old control points stay. The reconnection is Catmull-Clark's
//! ([`refined_topology`]), so the finer lattice has the same topology as a
//! Catmull-Clark refinement. Positions agree on an undeformed box grid (both
//! give the grid of half the spacing: grid points are linear data, which
//! both rule sets reproduce) and differ on a deformed lattice — the gap the
//! paper's hierarchical deformation corrects (§4.1).

use crate::error::Result;
use crate::stencil::{RowBuilder, StencilTable};

use super::lattice::Lattice;
use super::refine_topology::refined_topology;
use super::topology::LatticeTopology;

/// The octree map `O` from a lattice's control points to those of its
/// octree subdivision, rows numbered `[old | edge | face | cell]` like
/// [`refined_topology`]. Every row is an average, so rows sum to one.
pub fn octree_stencil(topo: &LatticeTopology) -> StencilTable {
    let nv = topo.num_vertices;
    let ne = topo.num_edges();
    let nf = topo.num_faces();
    let average = |vs: &[u32], b: &mut RowBuilder| {
        for &v in vs {
            b.add(v, 1.0 / vs.len() as f64);
        }
    };
    StencilTable::from_row_fn(nv + ne + nf + topo.num_cells(), nv, |r, b| {
        if r < nv {
            b.add(r as u32, 1.0);
        } else if r < nv + ne {
            average(&topo.edges[r - nv], b);
        } else if r < nv + ne + nf {
            average(topo.faces.row(r - nv - ne), b);
        } else {
            average(topo.cell_vertices.row(r - nv - ne - nf), b);
        }
    })
}

/// The octree subdivision of a lattice (automatic boundary tags) and the
/// map `O` that made its control points.
pub fn octree_refined(lattice: &Lattice) -> Result<(Lattice, StencilTable)> {
    let o = octree_stencil(&lattice.topology);
    let (topo, _) = refined_topology(&lattice.topology)?;
    let positions = o.apply(&lattice.positions)?;
    Ok((Lattice::new(positions, topo)?, o))
}

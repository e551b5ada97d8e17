//! Uniform refinement of a whole mesh to a level, with the size limits the
//! CLI and the Python package share.

use crate::error::{Error, Result};
use crate::math::Point3;
use crate::mesh::PolyMesh;

use super::Hierarchy;

/// Most uniform levels accepted (faces grow by 4× per level).
pub const MAX_LEVELS: usize = 8;
/// Most faces a refinement or tessellation may produce.
pub const MAX_FACES: usize = 50_000_000;

/// Faces after `levels` uniform Catmull-Clark levels: an `n`-gon becomes `n`
/// quads, then every quad becomes 4.
pub fn estimated_faces(mesh: &PolyMesh, levels: usize) -> f64 {
    if levels == 0 {
        return mesh.num_faces() as f64;
    }
    mesh.face_vertices.len() as f64 * 4f64.powi(levels as i32 - 1)
}

/// Refuses, before anything is allocated, more than [`MAX_LEVELS`] levels,
/// a refinement that would exceed [`MAX_FACES`] faces, or one whose memory
/// is over the budget ([`check_refinement_memory`]); `limit` counts the
/// limit stencils too.
pub fn check_uniform_size(mesh: &PolyMesh, levels: usize, limit: bool) -> Result<()> {
    if levels > MAX_LEVELS {
        return Err(Error::input(format!(
            "{levels} levels is too many: each level multiplies the faces by 4; at most {MAX_LEVELS} levels are allowed"
        )));
    }
    let faces = estimated_faces(mesh, levels);
    if faces > MAX_FACES as f64 {
        return Err(Error::input(format!(
            "{levels} levels would make about {:.0} million faces (at most {} million allowed); use fewer levels",
            faces / 1e6,
            MAX_FACES / 1_000_000
        )));
    }
    check_refinement_memory(faces, limit, &format!("{levels} levels"))
}

/// Bytes a refinement holds per face of its finest level (all levels'
/// topology, the stencils and the positions; measured on a 12,100-quad
/// torus: about 360 B at levels 3 and 4, and 920 B with the limit stencils,
/// which are wider).
const BYTES_PER_FACE: f64 = 400.0;
/// [`BYTES_PER_FACE`] with the limit stencils.
const BYTES_PER_LIMIT_FACE: f64 = 1100.0;

/// Refuses a refinement to `faces` faces (`limit`: with limit stencils)
/// whose estimated memory is over the budget ([`crate::memory`]); `what`
/// names it in the message.
pub fn check_refinement_memory(faces: f64, limit: bool, what: &str) -> Result<()> {
    let each = if limit {
        BYTES_PER_LIMIT_FACE
    } else {
        BYTES_PER_FACE
    };
    crate::memory::check_memory(
        &format!("{what} ({:.0} faces)", faces),
        (faces * each).min(u64::MAX as f64) as u64,
    )
}

/// Positions of level `levels` of `h` from the control points `p0`: refined
/// level by level (`P_{k+1} = S_k P_k`), or, with `limit`, moved to the limit
/// surface by the limit stencil of that level.
pub fn uniform_positions(
    h: &Hierarchy,
    p0: &[Point3],
    levels: usize,
    limit: bool,
) -> Result<Vec<Point3>> {
    if limit {
        return crate::limit::limit_stencil(h, levels)?.apply(p0);
    }
    h.refine_positions(p0)?
        .pop()
        .ok_or_else(|| Error::input("the refinement produced no level"))
}

//! The surface to rasterise (a [`crate::truth::GroundTruth`]: built-in shape
//! or mesh file) checked closed, and its crossings with lines parallel to z
//! through [`subdyn::metrics::TriangleBvh`].

use anyhow::{Context, Result, bail};
use subdyn::math::{Point3, Vector3, bounding_box};
use subdyn::mesh::PolyMesh;
use subdyn::metrics::TriangleBvh;

use crate::topology::mesh_topology;
use crate::volume::rasterise::ZCrossings;

/// Errors unless every edge of `mesh` has exactly two faces.
pub fn check_closed(mesh: &PolyMesh, what: &str) -> Result<()> {
    if mesh.num_faces() == 0 {
        bail!("{what}: the mesh has no faces; a volume needs a closed surface");
    }
    let t = mesh_topology(mesh);
    if !t.closed {
        bail!(
            "{what}: the mesh is not closed ({} boundary edges, {} edges with more than two faces); a volume needs a closed surface",
            t.boundary_edges,
            t.non_manifold_edges
        );
    }
    Ok(())
}

/// Bounding box of the mesh as arrays.
pub fn mesh_bounds(mesh: &PolyMesh) -> Result<([f64; 3], [f64; 3])> {
    let (lo, hi) = bounding_box(&mesh.positions).context("the mesh has no vertices")?;
    Ok(([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]))
}

/// A triangle mesh's crossings with lines parallel to z, by repeated BVH ray
/// casts: each cast starts just past the previous hit, so a line through a
/// shared edge or vertex (several triangles hit at one z) counts once.
pub struct MeshCrossings {
    bvh: TriangleBvh,
    /// Below the mesh.
    z_start: f64,
    /// Above the mesh.
    z_end: f64,
    /// How far past a hit the next cast starts.
    step: f64,
}

/// Casts per line before giving up (a line crossing more surface sheets than
/// this is treated as ending there).
const MAX_CROSSINGS: usize = 100_000;

impl MeshCrossings {
    /// Builds the BVH (polygons fan-triangulated from their first vertex).
    pub fn new(mesh: &PolyMesh) -> Result<MeshCrossings> {
        let (lo, hi) = mesh_bounds(mesh)?;
        let diag = (0..3)
            .map(|k| (hi[k] - lo[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        Ok(MeshCrossings {
            bvh: TriangleBvh::from_mesh(mesh)?,
            z_start: lo[2] - 1e-3 * diag,
            z_end: hi[2] + 1e-3 * diag,
            step: 1e-10 * diag,
        })
    }
}

impl ZCrossings for MeshCrossings {
    fn crossings(&self, x: f64, y: f64, out: &mut Vec<f64>) {
        let mut z = self.z_start;
        for _ in 0..MAX_CROSSINGS {
            match self
                .bvh
                .ray_cast(Point3::new(x, y, z), Vector3::z(), self.z_end - z)
            {
                Some(hit) => {
                    let at = z + hit.t;
                    out.push(at);
                    z = at + self.step;
                }
                None => break,
            }
        }
    }
}

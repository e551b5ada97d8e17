//! Dense limit-surface tessellation.

use crate::error::{Error, Result};
use crate::math::{Point3, Vector3};
use crate::mesh::PolyMesh;
use crate::subdivision::Refiner;

/// Tessellates every quad face (every quad sub-face of an n-gon) as a `k × k`
/// grid of limit samples. Returns the mesh and one unit normal per vertex.
/// Samples on shared edges and vertices are shared, so a closed control mesh
/// gives a watertight tessellation.
pub fn tessellate(refiner: &Refiner, positions: &[Point3], k: usize) -> Result<(PolyMesh, Vec<Vector3>)> {
    let _ = (refiner, positions, k);
    Err(Error::Input("limit tessellation is not implemented yet".into()))
}

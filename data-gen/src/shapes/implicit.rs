//! `implicit_mesh`: marching tetrahedra, then tangential relaxation on the
//! implicit surface.

use subdyn::error::Result;
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;

use super::marching_tets::marching_tetrahedra;
use super::relax::relaxed_on_surface;
use super::sdf::Field;

/// Relaxation steps after polygonisation.
const RELAX_ITERATIONS: usize = 8;

/// A closed triangle mesh of `field = 0` inside the box `[lo, hi]`, with
/// `resolution` grid cells along the box's longest side; every vertex lies on
/// the zero set (Newton-projected to ~1e-14 of the box size).
pub fn implicit_mesh(field: &Field, lo: Point3, hi: Point3, resolution: usize) -> Result<PolyMesh> {
    let extent = (hi - lo).amax();
    let cell = extent / resolution as Real;
    let mut mesh = marching_tetrahedra(field, lo, hi, cell)?;
    mesh.positions = relaxed_on_surface(&mesh, field, extent, RELAX_ITERATIONS);
    Ok(mesh)
}

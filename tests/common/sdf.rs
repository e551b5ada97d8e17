//! Analytic volumes for the recovery tests: a signed distance function
//! sampled as a ramp whose 0.5 level is the surface, written as raw f32
//! with its JSON header, and the distance of a recovered limit surface to it.

use subdyn::fit::recover::{PreparedVolume, RecoverParams, RecoverResult, recover_shape};
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{RefineOptions, Refiner};
use subdyn::volume::Volume;

/// A volume of `dims` voxels, spacing `spacing`, whose value at a voxel centre
/// is `clamp(0.5 − sdf / w, 0, 1)` for a signed distance `sdf` (negative
/// inside) and a ramp of width `w` (world units): the 0.5 level is the surface.
pub fn sdf_volume(dims: [usize; 3], spacing: [Real; 3], sdf: impl Fn(Point3) -> Real) -> Volume {
    let w = spacing.iter().cloned().fold(0.0, Real::max);
    let mut data = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = Point3::new(
                    i as Real * spacing[0],
                    j as Real * spacing[1],
                    k as Real * spacing[2],
                );
                data.push((0.5 - sdf(p) / w).clamp(0.0, 1.0) as f32);
            }
        }
    }
    Volume::new(dims, data, spacing, Point3::origin()).unwrap()
}

/// Largest and mean |sdf| over a dense limit tessellation of `control`.
pub fn surface_error(control: &PolyMesh, sdf: impl Fn(Point3) -> Real) -> (Real, Real) {
    let refiner = Refiner::new(control, &RefineOptions::default()).unwrap();
    let (tess, _) = tessellate(&refiner, &control.positions, 4).unwrap();
    let d: Vec<Real> = tess.positions.iter().map(|p| sdf(*p).abs()).collect();
    let max = d.iter().cloned().fold(0.0, Real::max);
    (max, d.iter().sum::<Real>() / d.len() as Real)
}

/// Writes `vol` as `dir/NAME.raw` (f32 little-endian) with its JSON header.
pub fn write_raw(dir: &std::path::Path, name: &str, vol: &Volume) -> std::path::PathBuf {
    let bytes: Vec<u8> = vol.data().iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join(format!("{name}.raw")), bytes).unwrap();
    let o = vol.origin();
    let header = serde_json::json!({
        "dims": vol.dims(), "spacing": vol.spacing(), "origin": [o.x, o.y, o.z],
        "dtype": "f32", "byte_order": "little", "header_bytes": 0,
    });
    std::fs::write(dir.join(format!("{name}.json")), header.to_string()).unwrap();
    dir.join(format!("{name}.raw"))
}

/// A ball of radius 9 centred at (16, 20, 24) with a rod 2 voxels thick
/// along x from 22 to 36 at y = 20, z = 20, plus deterministic noise of up
/// to 0.05: in a 42 × 40 × 32 grid its top is cut by the box, and the rod
/// is thinner than the automatic cage's blocks.
pub fn noisy_ball_with_rod(p: Point3) -> Real {
    let c = Point3::new(16.0, 20.0, 24.0);
    let (from, tip) = (Point3::new(22.0, 20.0, 20.0), Point3::new(36.0, 20.0, 20.0));
    let t = ((p - from).dot(&(tip - from)) / (tip - from).norm_squared()).clamp(0.0, 1.0);
    let rod = (p - (from + t * (tip - from))).norm() - 1.0;
    let noise = 0.05 * ((p.x * 12.9898 + p.y * 78.233 + p.z * 37.719).sin() * 43_758.545).fract();
    ((p - c).norm() - 9.0).min(rod) + noise
}

/// [`recover_shape`] from the cage `init` with its iso-surface points
/// `boundary`, no extra points and no progress.
pub fn recover_quietly(
    prepared: &PreparedVolume,
    init: &PolyMesh,
    boundary: &[Point3],
    params: &RecoverParams,
) -> RecoverResult {
    recover_shape(prepared, init, &[], boundary, params, &mut |_, _, _| {}).unwrap()
}

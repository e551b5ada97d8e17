//! [`InitKind::Closed`](super::InitKind::Closed): the genus-0 cage, an
//! ellipsoid-like 26-vertex / 24-quad mesh on the points' principal axes.
//!
//! Qin, Mandal and Vemuri (1998, §6) start every fit from a hand-made
//! control mesh "roughly" around the data; this builds one automatically.
//! The unit cube `[−1, 1]³` is refined once by Catmull-Clark (6 → 24 quads,
//! 8 corners of valence 3, 12 edge points and 6 face points of valence 4),
//! each refined vertex `q` is pushed radially onto the unit sphere, `q / |q|`,
//! and mapped onto the ellipsoid
//!
//! `x = m + Σ_k s_k (q_k / |q|) a_k`,
//!
//! whose centre `m` is the middle of the points' extents along the principal
//! axes `a_k` and whose semi-axes are half those extents,
//! `s_k = (hi_k − lo_k) / 2`. All control points lie on the ellipsoid, and the
//! Catmull-Clark limit surface lies inside the control net's convex hull, so
//! the initial limit surface sits *inside* the points: every data spring
//! then pulls outwards, which is the stable direction for the dynamic fit.
//! (For a unit sphere the limit surface of the cage lies between radii 0.82
//! and 0.85.)
//! Semi-axes are clamped below at 1 % of the largest so a flat cloud still
//! gives a non-degenerate cage. The frame is right-handed and the cube is
//! outward-oriented, so the cage is too; [`signed_volume`] confirms it.

use super::frame::PrincipalFrame;
use super::surface::{reversed, signed_volume};
use crate::error::Result;
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;
use crate::subdivision::{RefineOptions, Refiner};

/// Smallest semi-axis as a fraction of the largest.
const MIN_SEMI_AXIS: Real = 0.01;

/// Centre `m` and semi-axes `s_k` (local coordinates) of the ellipsoid
/// inscribed in the points' principal-axes box.
pub fn ellipsoid_axes(frame: &PrincipalFrame) -> (Vector3, [Real; 3]) {
    let ext = frame.extents();
    let largest = ext[0].max(ext[1]).max(ext[2]) / 2.0;
    let centre = Vector3::new(
        (frame.lo[0] + frame.hi[0]) / 2.0,
        (frame.lo[1] + frame.hi[1]) / 2.0,
        (frame.lo[2] + frame.hi[2]) / 2.0,
    );
    (centre, ext.map(|e| (e / 2.0).max(MIN_SEMI_AXIS * largest)))
}

/// The 26-vertex / 24-quad cage on the ellipsoid of [`ellipsoid_axes`],
/// outward-oriented (positive signed volume).
pub fn ellipsoid_cage(frame: &PrincipalFrame) -> Result<PolyMesh> {
    let cube = crate::examples::cube();
    let refiner = Refiner::new(&cube, &RefineOptions::default())?;
    let hierarchy = refiner.refine_uniform(1)?;
    let centred: Vec<Point3> = cube
        .positions
        .iter()
        .map(|p| Point3::from(p.coords * 2.0 - Vector3::repeat(1.0)))
        .collect();
    let refined = hierarchy.stencil_to_level(1)?.apply(&centred)?;
    let (centre, semi) = ellipsoid_axes(frame);
    let positions = refined
        .iter()
        .map(|q| {
            let u = q.coords.normalize();
            let l = centre + Vector3::new(semi[0] * u[0], semi[1] * u[1], semi[2] * u[2]);
            frame.world(&l)
        })
        .collect();
    let cage = hierarchy.mesh(1, positions);
    cage.validate()?;
    if signed_volume(&cage) < 0.0 {
        // Cannot happen for a right-handed frame; kept so the promise holds.
        return reversed(&cage);
    }
    Ok(cage)
}

//! The genus-2 surface: two tori side by side, blended by a smooth union.

use subdyn::error::Result;
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;

use super::implicit::implicit_mesh;
use super::sdf::{smooth_union, torus};

/// Major radius of each torus.
pub const MAJOR: Real = 1.0;
/// Minor (tube) radius of each torus.
pub const MINOR: Real = 0.4;
/// The tori are centred at `(±OFFSET, 0, 0)`; `OFFSET < MAJOR + MINOR` so the tubes merge.
pub const OFFSET: Real = 1.1;
/// Blend width of the smooth union.
pub const BLEND: Real = 0.1;

/// `f(p) = −k ln(e^{−T₁(p)/k} + e^{−T₂(p)/k})`, `Tᵢ` the distance to the torus
/// centred at `(∓OFFSET, 0, 0)` (axis z, radii `MAJOR`, `MINOR`), `k = BLEND`.
pub fn genus2_field(p: &Point3) -> Real {
    let left = torus(p, &Point3::new(-OFFSET, 0.0, 0.0), MAJOR, MINOR);
    let right = torus(p, &Point3::new(OFFSET, 0.0, 0.0), MAJOR, MINOR);
    smooth_union(&[left, right], BLEND)
}

/// The formula of [`genus2_field`], for sidecars.
pub const FORMULA: &str = "f(p) = -k ln(exp(-T1(p)/k) + exp(-T2(p)/k)), Ti(p) = sqrt((sqrt((x -+ c)^2 + y^2) - R)^2 + z^2) - r, c = 1.1, R = 1, r = 0.4, k = 0.1; inside f < 0";

/// The double torus, `resolution` grid cells along x.
pub fn genus2(resolution: usize) -> Result<PolyMesh> {
    let e = OFFSET + MAJOR + MINOR + 0.1;
    let lo = Point3::new(-e, -(MAJOR + MINOR + 0.1), -(MINOR + 0.1));
    let hi = Point3::new(e, MAJOR + MINOR + 0.1, MINOR + 0.1);
    implicit_mesh(&genus2_field, lo, hi, resolution)
}

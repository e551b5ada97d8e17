//! The anvil: a base, a waist and a face (rounded boxes) with a conical horn,
//! blended by a smooth union.

use subdyn::error::Result;
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;

use super::implicit::implicit_mesh;
use super::sdf::{round_box, round_cone, smooth_union};

/// Blend width of the smooth union.
pub const BLEND: Real = 0.04;

/// `f(p) = −k ln Σ exp(−dᵢ(p)/k)` over the pieces of the anvil (see [`FORMULA`]).
pub fn anvil_field(p: &Point3) -> Real {
    let base = round_box(
        p,
        &Point3::new(0.0, 0.0, 0.15),
        &Vector3::new(0.75, 0.5, 0.15),
        0.08,
    );
    let waist = round_box(
        p,
        &Point3::new(0.0, 0.0, 0.55),
        &Vector3::new(0.42, 0.27, 0.3),
        0.06,
    );
    let face = round_box(
        p,
        &Point3::new(0.15, 0.0, 1.0),
        &Vector3::new(0.8, 0.38, 0.18),
        0.08,
    );
    let horn = round_cone(
        p,
        &Point3::new(-0.55, 0.0, 0.98),
        &Point3::new(-1.4, 0.0, 1.08),
        0.2,
        0.035,
    );
    smooth_union(&[base, waist, face, horn], BLEND)
}

/// The pieces of [`anvil_field`], for sidecars.
pub const FORMULA: &str = "smooth union (k = 0.04) of: base = rounded box centre (0,0,0.15) half extents (0.75,0.5,0.15) rounding 0.08; waist = rounded box centre (0,0,0.55) half extents (0.42,0.27,0.3) rounding 0.06; face = rounded box centre (0.15,0,1) half extents (0.8,0.38,0.18) rounding 0.08; horn = round cone from (-0.55,0,0.98) radius 0.2 to (-1.4,0,1.08) radius 0.035; inside f < 0";

/// The anvil, `resolution` grid cells along x (its longest side, about 2.5).
pub fn anvil(resolution: usize) -> Result<PolyMesh> {
    let lo = Point3::new(-1.5, -0.55, -0.05);
    let hi = Point3::new(1.0, 0.55, 1.3);
    implicit_mesh(&anvil_field, lo, hi, resolution)
}

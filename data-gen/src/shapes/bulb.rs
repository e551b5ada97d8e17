//! The light bulb: a surface of revolution whose profile is a unit circle
//! blended into a cylindrical neck with a rounded end.

use subdyn::error::{Error, Result};
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;

use super::revolve::surface_of_revolution;
use super::sdf::{round_rect, smooth_union};

/// Blend width of the smooth union of globe and neck.
pub const BLEND: Real = 0.1;

/// Profile field in the `(ρ, z)` half plane: smooth union of the unit circle
/// and the neck, a rounded rectangle `ρ ≤ 0.42`, `−1.85 ≤ z ≤ −0.65`, corner radius 0.1.
pub fn profile_field(rho: Real, z: Real) -> Real {
    let globe = (rho * rho + z * z).sqrt() - 1.0;
    let neck = round_rect(rho, z, -1.25, 0.42, 0.6, 0.1);
    smooth_union(&[globe, neck], BLEND)
}

/// The bulb's field in space, `profile_field(√(x² + y²), z)`.
pub fn bulb_field(p: &Point3) -> Real {
    profile_field((p.x * p.x + p.y * p.y).sqrt(), p.z)
}

/// The formula of [`bulb_field`], for sidecars.
pub const FORMULA: &str = "f(p) = -k ln(exp(-G/k) + exp(-N/k)), rho = sqrt(x^2 + y^2), G = sqrt(rho^2 + z^2) - 1, N = rounded rectangle in (rho, z): |rho| <= 0.42, -1.85 <= z <= -0.65, corner radius 0.1; k = 0.1; inside f < 0";

/// The point the profile is star-shaped about (inside both globe and neck).
const CENTRE_Z: Real = -0.8;
/// Rays from the centre are searched up to this distance.
const REACH: Real = 2.0;

/// Distance from `(0, CENTRE_Z)` to the profile along direction `φ` (0 = +z),
/// failing if the ray crosses the profile more than once.
fn ray_root(phi: Real) -> Result<Real> {
    let (s, c) = phi.sin_cos();
    let f = |t: Real| profile_field(t * s, CENTRE_Z + t * c);
    let steps = 800;
    let dt = REACH / steps as Real;
    let mut crossing = None;
    for i in 0..steps {
        let (a, b) = (i as Real * dt, (i + 1) as Real * dt);
        if (f(a) < 0.0) != (f(b) < 0.0) {
            if crossing.is_some() {
                return Err(Error::input(format!(
                    "bulb profile is not star-shaped at angle {phi}"
                )));
            }
            crossing = Some((a, b));
        }
    }
    let (mut a, mut b) = crossing.ok_or_else(|| Error::input("bulb profile not found"))?;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m == a || m == b {
            break;
        }
        if f(m) < 0.0 { a = m } else { b = m }
    }
    Ok(0.5 * (a + b))
}

/// The light bulb: `resolution` profile steps (equal arc length) and
/// `resolution` segments around the axis.
pub fn bulb(resolution: usize) -> Result<PolyMesh> {
    // Arc length of the profile from dense samples, then equal-arc-length angles.
    let dense = 4096;
    let angles: Vec<Real> = (0..=dense)
        .map(|i| std::f64::consts::PI * i as Real / dense as Real)
        .collect();
    let points = angles
        .iter()
        .map(|&phi| ray_root(phi).map(|t| (t * phi.sin(), CENTRE_Z + t * phi.cos())))
        .collect::<Result<Vec<_>>>()?;
    let mut arc = vec![0.0];
    for w in points.windows(2) {
        let d = ((w[1].0 - w[0].0).powi(2) + (w[1].1 - w[0].1).powi(2)).sqrt();
        arc.push(arc.last().copied().unwrap_or(0.0) + d);
    }
    let total = arc[dense];
    let m = resolution;
    let mut profile = Vec::with_capacity(m + 1);
    let mut k = 0;
    for i in 0..=m {
        let s = total * i as Real / m as Real;
        while k + 1 < dense && arc[k + 1] < s {
            k += 1;
        }
        let w = ((s - arc[k]) / (arc[k + 1] - arc[k])).clamp(0.0, 1.0);
        let phi = angles[k] + w * (angles[k + 1] - angles[k]);
        let phi = if i == 0 {
            0.0
        } else if i == m {
            std::f64::consts::PI
        } else {
            phi
        };
        let t = ray_root(phi)?;
        let rho = if i == 0 || i == m { 0.0 } else { t * phi.sin() };
        profile.push((rho, CENTRE_Z + t * phi.cos()));
    }
    surface_of_revolution(&profile, resolution)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_vertices_lie_on_the_field() {
        let mesh = bulb(24).unwrap();
        for p in &mesh.positions {
            assert!(bulb_field(p).abs() < 1e-12, "{p:?}");
        }
        let t = crate::topology::mesh_topology(&mesh);
        assert_eq!(t.genus, Some(0));
    }
}

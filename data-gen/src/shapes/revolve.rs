//! `surface_of_revolution`: a closed mesh swept from a profile curve around
//! the z axis.

use subdyn::error::{Error, Result};
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;

/// Sweeps `profile` — points `(ρ, z)` from the north pole (`ρ = 0`) to the
/// south pole (`ρ = 0`), `ρ > 0` in between — around the z axis in `segments`
/// steps: triangle fans at the poles, quads elsewhere, outward orientation.
/// `V = 2 + (m − 1)s`, `E = (2m − 1)s`, `F = ms` for `m + 1` profile points, so χ = 2.
pub fn surface_of_revolution(profile: &[(Real, Real)], segments: usize) -> Result<PolyMesh> {
    let m = profile.len().saturating_sub(1);
    if m < 2 || segments < 3 {
        return Err(Error::input(
            "a surface of revolution needs 3 profile points and 3 segments",
        ));
    }
    if profile[0].0 != 0.0 || profile[m].0 != 0.0 || profile[1..m].iter().any(|p| p.0 <= 0.0) {
        return Err(Error::input(
            "the profile must start and end on the axis and stay off it in between",
        ));
    }
    let s = segments;
    let mut positions = vec![Point3::new(0.0, 0.0, profile[0].1)];
    for &(rho, z) in &profile[1..m] {
        for j in 0..s {
            let a = std::f64::consts::TAU * j as Real / s as Real;
            positions.push(Point3::new(rho * a.cos(), rho * a.sin(), z));
        }
    }
    positions.push(Point3::new(0.0, 0.0, profile[m].1));
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * s + j % s) as u32;
    let mut faces = Vec::with_capacity(m * s);
    // Going down the profile and counter-clockwise around z: outward is
    // (down) × (around)… checked: the north fan (0, ring(1, j), ring(1, j+1)).
    for j in 0..s {
        faces.push(vec![0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..m - 1 {
        for j in 0..s {
            faces.push(vec![
                ring(i, j),
                ring(i + 1, j),
                ring(i + 1, j + 1),
                ring(i, j + 1),
            ]);
        }
    }
    for j in 0..s {
        faces.push(vec![ring(m - 1, j), south, ring(m - 1, j + 1)]);
    }
    PolyMesh::from_faces(positions, &faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::mesh_topology;

    #[test]
    fn a_half_circle_sweeps_to_an_outward_sphere() {
        let m = 12;
        let profile: Vec<(Real, Real)> = (0..=m)
            .map(|i| {
                let t = std::f64::consts::PI * i as Real / m as Real;
                (if i == 0 || i == m { 0.0 } else { t.sin() }, t.cos())
            })
            .collect();
        let mesh = surface_of_revolution(&profile, 16).unwrap();
        let t = mesh_topology(&mesh);
        assert!(t.closed_manifold, "{t:?}");
        assert_eq!(t.euler_characteristic, 2);
        assert!(crate::measure::enclosed_volume(&mesh) > 3.9);
    }
}

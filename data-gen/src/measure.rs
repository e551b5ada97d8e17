//! Area, enclosed volume and outward orientation of a polygon mesh (faces
//! fanned into triangles from their first vertex).

use subdyn::math::Real;
use subdyn::mesh::PolyMesh;

/// `Σ_faces |fan area|`: the surface area of the mesh.
pub fn surface_area(mesh: &PolyMesh) -> Real {
    mesh.faces()
        .map(|f| {
            let p = |i: usize| mesh.positions[f[i] as usize];
            (1..f.len() - 1)
                .map(|i| 0.5 * (p(i) - p(0)).cross(&(p(i + 1) - p(0))).norm())
                .sum::<Real>()
        })
        .sum()
}

/// `V = (1/6) Σ_triangles a · (b × c)`: the signed volume enclosed by a closed
/// mesh (positive when the faces turn counter-clockwise seen from outside).
pub fn enclosed_volume(mesh: &PolyMesh) -> Real {
    // Relative to the first vertex, which keeps the sum well conditioned far from the origin.
    let Some(&o) = mesh.positions.first() else {
        return 0.0;
    };
    mesh.faces()
        .map(|f| {
            let p = |i: usize| mesh.positions[f[i] as usize] - o;
            (1..f.len() - 1)
                .map(|i| p(0).dot(&p(i).cross(&p(i + 1))) / 6.0)
                .sum::<Real>()
        })
        .sum()
}

/// Reverses every face when the enclosed volume is negative, so normals point out.
pub fn orient_outward(mesh: &mut PolyMesh) {
    if enclosed_volume(mesh) < 0.0 {
        for f in 0..mesh.num_faces() {
            let (a, b) = (
                mesh.face_offsets[f] as usize,
                mesh.face_offsets[f + 1] as usize,
            );
            mesh.face_vertices[a..b].reverse();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_cube_area_and_volume() {
        let cube = subdyn::examples::cube();
        assert!((surface_area(&cube) - 6.0).abs() < 1e-12);
        assert!((enclosed_volume(&cube) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn orientation_is_fixed() {
        let mut cube = subdyn::examples::cube();
        let n = cube.face_vertices.len();
        cube.face_vertices[..n].reverse();
        // Reversing the whole array reverses each face and the face order; offsets of equal-size faces still match.
        assert!(enclosed_volume(&cube) < 0.0);
        orient_outward(&mut cube);
        assert!((enclosed_volume(&cube) - 1.0).abs() < 1e-12);
    }
}

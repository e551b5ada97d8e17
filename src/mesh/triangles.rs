//! `split_quads`: a triangle mesh that every mesh tool reads, from a
//! tessellation of quads.

use crate::math::{Point3, Real, Vector3};

use super::PolyMesh;

/// Splits every quad `a b c d` into two triangles along the diagonal whose
/// two triangles face the same way best: `a c` gives `(a b c), (a c d)`,
/// `b d` gives `(a b d), (b c d)`, and the one with the larger cosine between
/// the two triangle normals is taken (`a c` on a tie). A non-convex or
/// strongly bent quad (near an extraordinary vertex of a limit tessellation)
/// thus never gets a fold. Triangles are kept; a larger polygon is fanned
/// from its first vertex. Positions are shared, not copied per face; the
/// faces of face `f` come in the order of `f`.
///
/// ```
/// use subdyn::{math::Point3, mesh::{PolyMesh, split_quads}};
/// // A quad bent along b d: its two triangles there agree better than along a c.
/// let p = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
///              Point3::new(1.0, 1.0, 1.0), Point3::new(0.0, 1.0, 0.0)];
/// let quad = PolyMesh::from_faces(p, &[vec![0, 1, 2, 3]])?;
/// let tri = split_quads(&quad);
/// assert_eq!(tri.face(0), &[0, 1, 3]);
/// assert_eq!(tri.face(1), &[1, 2, 3]);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn split_quads(mesh: &PolyMesh) -> PolyMesh {
    let p = &mesh.positions;
    let triangles: usize = mesh.faces().map(|f| f.len() - 2).sum();
    let mut face_vertices = Vec::with_capacity(3 * triangles);
    for f in mesh.faces() {
        match *f {
            [a, b, c, d] => {
                let along_ac = normal_cosine(p, [a, b, c], [a, c, d]);
                let along_bd = normal_cosine(p, [a, b, d], [b, c, d]);
                if along_ac >= along_bd {
                    face_vertices.extend_from_slice(&[a, b, c, a, c, d]);
                } else {
                    face_vertices.extend_from_slice(&[a, b, d, b, c, d]);
                }
            }
            _ => {
                for i in 1..f.len() - 1 {
                    face_vertices.extend_from_slice(&[f[0], f[i], f[i + 1]]);
                }
            }
        }
    }
    PolyMesh {
        positions: mesh.positions.clone(),
        face_offsets: (0..=triangles as u32).map(|t| 3 * t).collect(),
        face_vertices,
    }
}

/// Cosine of the angle between the normals of two triangles; −1 (the worst)
/// when either has no area.
fn normal_cosine(p: &[Point3], s: [u32; 3], t: [u32; 3]) -> Real {
    let n = |[a, b, c]: [u32; 3]| -> Vector3 {
        let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
        (b - a).cross(&(c - a))
    };
    let (m, n) = (n(s), n(t));
    let len = m.norm() * n.norm();
    if len > 0.0 { m.dot(&n) / len } else { -1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_quad_splits_along_a_c_and_keeps_its_vertices() {
        let p = |x, y| Point3::new(x, y, 0.0);
        let quad = PolyMesh::from_faces(
            vec![p(0., 0.), p(1., 0.), p(1., 1.), p(0., 1.)],
            &[vec![0, 1, 2, 3]],
        )
        .unwrap();
        let tri = split_quads(&quad);
        assert_eq!(tri.positions, quad.positions);
        assert_eq!(tri.face_vertices, vec![0, 1, 2, 0, 2, 3]);
        tri.validate().unwrap();
    }

    #[test]
    fn a_non_convex_quad_splits_at_its_reflex_corner() {
        // An arrowhead: corner 2 is reflex, so the a c diagonal (0–2) stays
        // inside and both triangles face +z; b d (1–3) would flip one.
        let p = |x, y| Point3::new(x, y, 0.0);
        let quad = PolyMesh::from_faces(
            vec![p(0., 0.), p(2., 1.), p(0.5, 0.5), p(1., 2.)],
            &[vec![0, 1, 2, 3]],
        )
        .unwrap();
        let tri = split_quads(&quad);
        assert_eq!(tri.face_vertices, vec![0, 1, 2, 0, 2, 3]);
        // The same quad listed from corner 1: now b d is the inside diagonal.
        let quad = PolyMesh::from_faces(quad.positions.clone(), &[vec![1, 2, 3, 0]]).unwrap();
        assert_eq!(split_quads(&quad).face_vertices, vec![1, 2, 0, 2, 3, 0]);
        for t in split_quads(&quad).faces() {
            let n = (quad.positions[t[1] as usize] - quad.positions[t[0] as usize])
                .cross(&(quad.positions[t[2] as usize] - quad.positions[t[0] as usize]));
            assert!(n.z > 0.0, "triangle {t:?} faces down");
        }
    }

    #[test]
    fn triangles_stay_and_polygons_fan() {
        let p = |x, y| Point3::new(x, y, 0.0);
        let mesh = PolyMesh::from_faces(
            vec![p(0., 0.), p(1., 0.), p(1.5, 1.), p(0.5, 1.5), p(-0.5, 1.)],
            &[vec![0, 1, 2, 3, 4], vec![0, 1, 2]],
        )
        .unwrap();
        let tri = split_quads(&mesh);
        assert_eq!(tri.face_vertices, vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 2]);
    }
}

//! Normals for shading and the lighting model: Lambert with a headlight,
//! a little ambient light, two-sided.

use crate::math::{Real, Vector3, newell_normal};
use crate::mesh::PolyMesh;

/// Fraction of full brightness that every lit surface gets (ambient light).
pub const AMBIENT: f32 = 0.18;

/// A light that moves with the camera: it shines from the eye, tilted a
/// little up and to the left so that flat faces seen head-on still show
/// their shape.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Headlight {
    towards_eye: Vector3,
    towards_light: Vector3,
}

impl Headlight {
    /// The headlight of a camera with the given eye direction and picture axes.
    pub fn new(towards_eye: Vector3, right: Vector3, up: Vector3) -> Headlight {
        let l = towards_eye + 0.3 * up - 0.2 * right;
        Headlight {
            towards_eye,
            towards_light: l.normalize(),
        }
    }

    /// Lambert brightness in `[AMBIENT, 1]` of a surface with normal `n`
    /// (any length, any orientation): the normal is first turned towards the
    /// eye, so both sides of a surface are lit (two-sided lighting).
    pub fn brightness(&self, n: &Vector3) -> f32 {
        let len = n.norm();
        if len.is_nan() || len <= 0.0 {
            return AMBIENT;
        }
        let mut n = n / len;
        if n.dot(&self.towards_eye) < 0.0 {
            n = -n;
        }
        let lambert = n.dot(&self.towards_light).max(0.0) as f32;
        AMBIENT + (1.0 - AMBIENT) * lambert
    }
}

/// Multiplies an sRGB colour by a brightness.
pub(crate) fn lit(color: [f32; 3], brightness: f32) -> [f32; 3] {
    color.map(|c| c * brightness)
}

/// Area-weighted normal of every face (Newell's method, so non-planar
/// polygons get their best-fit normal; the length is the polygon's area).
pub fn face_normals(mesh: &PolyMesh) -> Vec<Vector3> {
    mesh.faces()
        .map(|f| newell_normal(&mesh.positions, f) / 2.0)
        .collect()
}

/// One unit normal per face corner (aligned with `mesh.face_vertices`),
/// smooth across edges where neighbouring faces meet at less than
/// `crease_deg` degrees and sharp where they meet at more: the corner's
/// normal averages (area-weighted) only those faces around its vertex whose
/// normal is within `crease_deg` of its own face's normal. A corner of a
/// zero-area face gets a zero vector (drawn with ambient light only).
pub fn corner_normals(mesh: &PolyMesh, crease_deg: Real) -> Vec<Vector3> {
    let normals = face_normals(mesh);
    let unit: Vec<Vector3> = normals
        .iter()
        .map(|n| n.try_normalize(0.0).unwrap_or_else(Vector3::zeros))
        .collect();
    // Faces around each vertex, in CSR form.
    let (start, around) = crate::math::group_by_key(
        mesh.num_vertices(),
        (0..mesh.num_faces())
            .flat_map(|f| mesh.face(f).iter().map(move |&v| (v as usize, f as u32))),
    );
    let cos_crease = crease_deg.clamp(0.0, 180.0).to_radians().cos();
    let mut out = Vec::with_capacity(mesh.face_vertices.len());
    for (f, face) in mesh.faces().enumerate() {
        for &v in face {
            let mut n = Vector3::zeros();
            for &g in &around[start[v as usize]..start[v as usize + 1]] {
                if unit[g as usize].dot(&unit[f]) >= cos_crease {
                    n += normals[g as usize];
                }
            }
            out.push(n.try_normalize(0.0).unwrap_or(unit[f]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_corner_is_sharp_below_90_degrees_and_smooth_above() {
        let cube = crate::examples::cube();
        let sharp = corner_normals(&cube, 45.0);
        let fns = face_normals(&cube);
        for (f, face) in cube.faces().enumerate() {
            let off = cube.face_offsets[f] as usize;
            for k in 0..face.len() {
                assert!((sharp[off + k] - fns[f].normalize()).norm() < 1e-12);
            }
        }
        let smooth = corner_normals(&cube, 100.0);
        let p = cube.positions[cube.face(0)[0] as usize];
        let centre = cube.positions.iter().map(|q| q.coords).sum::<Vector3>() / 8.0;
        let radial = (p.coords - centre).normalize();
        assert!((smooth[0] - radial).norm() < 1e-12);
    }

    #[test]
    fn both_sides_are_lit_alike() {
        let light = Headlight::new(Vector3::z(), Vector3::x(), Vector3::y());
        let n = Vector3::new(0.2, 0.1, 1.0);
        assert_eq!(light.brightness(&n), light.brightness(&-n));
        assert!(light.brightness(&Vector3::z()) > 0.9);
        assert_eq!(light.brightness(&Vector3::zeros()), AMBIENT);
    }
}

//! `relaxed_on_surface`: tangential Laplacian relaxation of a mesh whose
//! vertices lie on the zero set of a field, re-projecting after every step.
//! Evens out the slivers of marching tetrahedra without moving the mesh off
//! the implicit surface.

use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;

use super::sdf::{Field, gradient, project};

/// Positions after `iterations` steps of `p ← π(p + λ (L − (L·n) n))`, where
/// `L` is the umbrella vector (mean of the neighbours minus `p`), `n = ∇f/|∇f|`
/// and `π` is Newton projection onto `f = 0`. `scale` is a length of the
/// order of the shape (sets the gradient step and the tolerance); `λ = 0.5`.
/// A vertex whose move would flip one of its faces against `∇f` stays put.
pub fn relaxed_on_surface(
    mesh: &PolyMesh,
    field: &Field,
    scale: Real,
    iterations: usize,
) -> Vec<Point3> {
    let nv = mesh.num_vertices();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut vertex_faces: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (f, face) in mesh.faces().enumerate() {
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
            vertex_faces[a as usize].push(f as u32);
        }
    }
    for ns in &mut neighbours {
        ns.sort_unstable();
        ns.dedup();
    }
    let h = 1e-7 * scale;
    let tol = 1e-14 * scale;
    let mut p = mesh.positions.clone();
    for _ in 0..iterations {
        let mut next = p.clone();
        for v in 0..nv {
            let ns = &neighbours[v];
            if ns.is_empty() {
                continue;
            }
            let mean = ns
                .iter()
                .fold(Vector3::zeros(), |s, &u| s + p[u as usize].coords)
                / ns.len() as Real;
            let l = mean - p[v].coords;
            let g = gradient(field, &p[v], h);
            let Some(n) = g.try_normalize(1e-12) else {
                continue;
            };
            let moved = p[v] + (l - n * l.dot(&n)) * 0.5;
            let candidate = project(field, &moved, h, tol, l.norm() + scale * 1e-3);
            let keeps_orientation = vertex_faces[v].iter().all(|&f| {
                let face = mesh.face(f as usize);
                let q = |u: u32| {
                    if u as usize == v {
                        candidate
                    } else {
                        p[u as usize]
                    }
                };
                let (a, b, c) = (q(face[0]), q(face[1]), q(face[2]));
                (b - a).cross(&(c - a)).dot(&n) > 0.0
            });
            if keeps_orientation && field(&candidate).abs() <= 1e3 * tol {
                next[v] = candidate;
            }
        }
        p = next;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::marching_tets::marching_tetrahedra;

    #[test]
    fn relaxation_keeps_vertices_on_the_sphere_and_improves_the_worst_triangle() {
        let sphere = |p: &Point3| p.coords.norm() - 1.0;
        let lo = Point3::new(-1.1, -1.1, -1.1);
        let mesh = marching_tetrahedra(&sphere, lo, Point3::new(1.1, 1.1, 1.1), 0.15).unwrap();
        let min_angle = |p: &[Point3]| {
            mesh.faces()
                .map(|f| {
                    let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
                    let ang = |x: Point3, y: Point3, z: Point3| (y - x).angle(&(z - x));
                    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
                })
                .fold(Real::INFINITY, Real::min)
        };
        let relaxed = relaxed_on_surface(&mesh, &sphere, 1.0, 10);
        for q in &relaxed {
            assert!((q.coords.norm() - 1.0).abs() < 1e-12);
        }
        assert!(min_angle(&relaxed) > min_angle(&mesh.positions));
    }
}

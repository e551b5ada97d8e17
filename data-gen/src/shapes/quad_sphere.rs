//! `quad_sphere`: the cube `[-1, 1]³` with `n × n` quads per face, pushed
//! onto the unit sphere through the equi-angular map `c ↦ tan(π c / 4)`, then
//! normalised (quads of nearly equal size, no poles). Scaled per axis it is
//! the ellipsoid.

use std::collections::HashMap;

use subdyn::error::Result;
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;

/// The unit quad sphere with `n × n` quads on each of the six cube faces:
/// `6n² + 2` vertices, `12n²` edges, `6n²` faces (χ = 2). Faces turn
/// counter-clockwise seen from outside.
pub fn quad_sphere(n: usize) -> Result<PolyMesh> {
    let n = n.max(1) as i64;
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions: Vec<Point3> = Vec::new();
    let mut id = |c: [i64; 3], positions: &mut Vec<Point3>| -> u32 {
        *ids.entry(c).or_insert_with(|| {
            let warp =
                |i: i64| (std::f64::consts::FRAC_PI_4 * (2.0 * i as Real / n as Real - 1.0)).tan();
            let v = Vector3::new(warp(c[0]), warp(c[1]), warp(c[2]));
            positions.push(Point3::from(v.normalize()));
            positions.len() as u32 - 1
        })
    };
    let mut faces = Vec::with_capacity(6 * (n * n) as usize);
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, n] {
            // (u, v, axis) is right-handed, so u × v points along +axis:
            // counter-clockwise in (u, v) is outward on the +axis side.
            let outward_is_ccw = side == n;
            for a in 0..n {
                for b in 0..n {
                    let lattice = |da: i64, db: i64| {
                        let mut c = [0i64; 3];
                        c[axis] = side;
                        c[u] = a + da;
                        c[v] = b + db;
                        c
                    };
                    let mut quad: Vec<u32> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                        .iter()
                        .map(|&(da, db)| id(lattice(da, db), &mut positions))
                        .collect();
                    if !outward_is_ccw {
                        quad.reverse();
                    }
                    faces.push(quad);
                }
            }
        }
    }
    PolyMesh::from_faces(positions, &faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::mesh_topology;

    #[test]
    fn counts_orientation_and_radius() {
        let s = quad_sphere(5).unwrap();
        let t = mesh_topology(&s);
        assert_eq!((t.vertices, t.edges, t.faces), (152, 300, 150));
        assert!(t.closed_manifold);
        assert_eq!(t.genus, Some(0));
        assert!(crate::measure::enclosed_volume(&s) > 3.5);
        for p in &s.positions {
            assert!((p.coords.norm() - 1.0).abs() < 1e-15);
        }
    }
}

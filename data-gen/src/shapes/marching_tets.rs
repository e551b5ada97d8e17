//! `marching_tetrahedra`: the zero set of a scalar field as a closed,
//! oriented triangle mesh.
//!
//! Each grid cube is split into the six Kuhn (Freudenthal) tetrahedra around
//! its main diagonal, a split that neighbouring cubes agree on. The mesh is
//! then the zero set of the piecewise-linear interpolant of the grid values,
//! so it is a closed 2-manifold whenever no grid value is exactly zero (zeros
//! count as outside) and the field is positive on the grid's boundary. Vertices
//! are shared by grid edge and placed on the field's true root along the edge
//! (Illinois regula falsi), not the linear estimate.

use std::collections::HashMap;

use subdyn::error::{Error, Result};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;

use super::sdf::Field;

/// The six tetrahedra of a cube (corner `c` at offset `(c & 1, c >> 1 & 1, c >> 2 & 1)`),
/// one per axis order: `0 → eₐ → eₐ + e_b → 7`.
const TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Polygonises `field` on a grid of cubes of side `cell` covering `[lo, hi]`
/// (the grid is shifted by a fixed fraction of a cell so that symmetric
/// shapes do not put zeros on grid points). Fails when the field is not
/// positive on the whole boundary of the grid (the shape would be cut open).
pub fn marching_tetrahedra(field: &Field, lo: Point3, hi: Point3, cell: Real) -> Result<PolyMesh> {
    let shift = Vector3::new(0.1234, 0.2345, 0.3456) * cell;
    let origin = lo - Vector3::repeat(cell) - shift;
    let n: [usize; 3] = std::array::from_fn(|k| ((hi[k] - origin[k]) / cell).ceil() as usize + 1);
    let (nx, ny, nz) = (n[0] + 1, n[1] + 1, n[2] + 1);
    if nx * ny * nz > 200_000_000 {
        return Err(Error::input(format!(
            "a {}×{}×{} grid is too large; lower the resolution",
            n[0], n[1], n[2]
        )));
    }
    let index = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
    let point = |g: usize| {
        let (i, j, k) = (g % nx, (g / nx) % ny, g / (nx * ny));
        origin + Vector3::new(i as Real, j as Real, k as Real) * cell
    };
    let values: Vec<Real> = (0..nx * ny * nz).map(|g| field(&point(g))).collect();
    for (g, &value) in values.iter().enumerate() {
        let (i, j, k) = (g % nx, (g / nx) % ny, g / (nx * ny));
        let on_boundary = i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1;
        if on_boundary && value <= 0.0 {
            return Err(Error::input(
                "the shape reaches the boundary of its polygonisation grid",
            ));
        }
    }

    let mut vertex_of_edge: HashMap<(u32, u32), u32> = HashMap::new();
    let mut positions: Vec<Point3> = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let tol = 1e-13 * cell;
    let mut vertex = |a: usize, b: usize, positions: &mut Vec<Point3>| -> u32 {
        let key = (a.min(b) as u32, a.max(b) as u32);
        *vertex_of_edge.entry(key).or_insert_with(|| {
            // a inside (negative), b outside.
            let (pa, pb, fa, fb) = if values[a] < 0.0 {
                (point(a), point(b), values[a], values[b])
            } else {
                (point(b), point(a), values[b], values[a])
            };
            positions.push(edge_root(field, pa, pb, fa, fb, tol));
            positions.len() as u32 - 1
        })
    };

    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let corner = |c: usize| index(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
                for tet in &TETS {
                    let g: [usize; 4] = std::array::from_fn(|t| corner(tet[t]));
                    let inside: Vec<usize> =
                        g.iter().copied().filter(|&v| values[v] < 0.0).collect();
                    let outside: Vec<usize> =
                        g.iter().copied().filter(|&v| values[v] >= 0.0).collect();
                    let polygon: Vec<(usize, usize)> = match inside.len() {
                        1 => outside.iter().map(|&o| (inside[0], o)).collect(),
                        3 => inside.iter().map(|&i| (i, outside[0])).collect(),
                        2 => {
                            let (a, b, c, d) = (inside[0], inside[1], outside[0], outside[1]);
                            vec![(a, c), (a, d), (b, d), (b, c)]
                        }
                        _ => continue,
                    };
                    // Orientation from the edge midpoints: the zero set of the
                    // ±1 interpolant, whose gradient points from inside to outside.
                    let mid: Vec<Point3> = polygon
                        .iter()
                        .map(|&(a, b)| point(a) + (point(b) - point(a)) * 0.5)
                        .collect();
                    let centroid = |vs: &[usize]| {
                        vs.iter()
                            .fold(Vector3::zeros(), |s, &v| s + point(v).coords)
                            / vs.len() as Real
                    };
                    let outward = centroid(&outside) - centroid(&inside);
                    let normal = (mid[1] - mid[0]).cross(&(mid[2] - mid[0]));
                    let mut ids: Vec<u32> = polygon
                        .iter()
                        .map(|&(a, b)| vertex(a, b, &mut positions))
                        .collect();
                    if normal.dot(&outward) < 0.0 {
                        ids.reverse();
                    }
                    if ids.len() == 3 {
                        faces.push(ids);
                    } else {
                        faces.push(vec![ids[0], ids[1], ids[2]]);
                        faces.push(vec![ids[0], ids[2], ids[3]]);
                    }
                }
            }
        }
    }
    PolyMesh::from_faces(positions, &faces)
}

/// The root of `field` on the segment from `pa` (`fa < 0`) to `pb` (`fb ≥ 0`),
/// by Illinois regula falsi to within `tol` along the segment.
fn edge_root(field: &Field, pa: Point3, pb: Point3, fa: Real, fb: Real, tol: Real) -> Point3 {
    let len = (pb - pa).norm();
    let at = |t: Real| pa + (pb - pa) * t;
    let (mut t0, mut t1, mut f0, mut f1) = (0.0, 1.0, fa, fb);
    let mut side = 0;
    for _ in 0..100 {
        if (t1 - t0) * len <= tol {
            break;
        }
        let mut t = (t0 * f1 - t1 * f0) / (f1 - f0);
        if !(t > t0 && t < t1) {
            t = 0.5 * (t0 + t1);
        }
        let f = field(&at(t));
        if f == 0.0 {
            return at(t);
        }
        if f < 0.0 {
            t0 = t;
            f0 = f;
            if side == -1 {
                f1 *= 0.5;
            }
            side = -1;
        } else {
            t1 = t;
            f1 = f;
            if side == 1 {
                f0 *= 0.5;
            }
            side = 1;
        }
    }
    // The end with the smaller |f|.
    if f0.abs() < f1.abs() { at(t0) } else { at(t1) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::mesh_topology;

    #[test]
    fn sphere_is_closed_genus_zero_and_on_the_surface() {
        let sphere = |p: &Point3| p.coords.norm() - 1.0;
        let lo = Point3::new(-1.2, -1.2, -1.2);
        let hi = Point3::new(1.2, 1.2, 1.2);
        let mesh = marching_tetrahedra(&sphere, lo, hi, 0.1).unwrap();
        let t = mesh_topology(&mesh);
        assert!(t.closed_manifold, "{t:?}");
        assert_eq!(t.euler_characteristic, 2);
        for p in &mesh.positions {
            assert!((p.coords.norm() - 1.0).abs() < 1e-12);
        }
        assert!(crate::measure::enclosed_volume(&mesh) > 4.0);
    }

    #[test]
    fn a_shape_touching_the_grid_boundary_is_refused() {
        let big = |p: &Point3| p.coords.norm() - 10.0;
        let lo = Point3::new(-1.0, -1.0, -1.0);
        assert!(marching_tetrahedra(&big, lo, Point3::new(1.0, 1.0, 1.0), 0.5).is_err());
    }
}

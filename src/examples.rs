//! Small embedded meshes for docs, tests and the CLI's default run.

use crate::math::Point3;
use crate::mesh::PolyMesh;

/// The unit cube `[0, 1]³` as six quads (outward normals), vertex `i` at
/// `(i >> 2 & 1, i >> 1 & 1, i & 1)` — the same as OpenSubdiv's reference `cube.obj`.
pub fn cube() -> PolyMesh {
    let positions = (0..8)
        .map(|i| Point3::new((i >> 2 & 1) as f64, (i >> 1 & 1) as f64, (i & 1) as f64))
        .collect();
    let faces = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let faces: Vec<Vec<u32>> = faces.iter().map(|f| f.to_vec()).collect();
    PolyMesh::from_faces(positions, &faces).expect("the cube is valid")
}

/// An `n × m` quad torus with major radius `r_major` and minor radius `r_minor`.
pub fn torus(n: usize, m: usize, r_major: f64, r_minor: f64) -> PolyMesh {
    use std::f64::consts::TAU;
    let mut positions = Vec::with_capacity(n * m);
    for i in 0..n {
        let a = TAU * i as f64 / n as f64;
        for j in 0..m {
            let b = TAU * j as f64 / m as f64;
            let r = r_major + r_minor * b.cos();
            positions.push(Point3::new(r * a.cos(), r * a.sin(), r_minor * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolyMesh::from_faces(positions, &faces).expect("the torus is valid")
}

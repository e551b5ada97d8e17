//! Fairness of the control net: the umbrella energy that keeps a fit's
//! control points from shooting out into spikes.
//!
//! A Catmull-Clark limit point is a weighted average of its control point
//! and the ring around it, so to pull the limit surface into a feature
//! narrower than its faces (a horn, an ear, a sharp edge) the springs move
//! control points several times farther out than the surface goes. The
//! thin plate of Qin, Mandal and Vemuri (1998, eq. 12) measures the limit
//! surface's parametric derivatives and lets such a tangled net pass: the
//! limit surface then pleats and passes through itself. The umbrella
//! operator `Δp_v = mean(ring of v) − p_v` (Taubin 1995, "A signal
//! processing approach to fair surface design", eq. 4 with equal weights;
//! Kobbelt et al. 1998, "Interactive multi-resolution modeling on arbitrary
//! meshes", §3) measures the net itself; its energy
//! `½ Σ_v w_v |Δp_v|² = ½ pᵀ Lᵀ W L p` is added to the thin plate.
//! `L` couples a vertex with its ring, `LᵀL` a vertex with the rings of its
//! neighbours, all within the support of one of the vertex's patches, so
//! the matrix fits the pattern of [`crate::forces::PatchAssembly`].

use std::collections::BTreeMap;

use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;

/// Each vertex's neighbours along edges, sorted.
pub fn vertex_rings(mesh: &PolyMesh) -> Vec<Vec<u32>> {
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); mesh.num_vertices()];
    for f in mesh.faces() {
        for (i, &a) in f.iter().enumerate() {
            let b = f[(i + 1) % f.len()];
            ring[a as usize].push(b);
            ring[b as usize].push(a);
        }
    }
    for r in &mut ring {
        r.sort_unstable();
        r.dedup();
    }
    ring
}

/// `Lᵀ W L` (module docs) for the rings `ring` and weights `w` (one per
/// vertex; zero leaves a vertex out), as a square matrix over the vertices.
pub fn umbrella_matrix(ring: &[Vec<u32>], w: &[Real]) -> StencilTable {
    let n = ring.len();
    let mut rows: Vec<BTreeMap<u32, Real>> = vec![BTreeMap::new(); n];
    for (v, r) in ring.iter().enumerate() {
        if w[v] == 0.0 || r.is_empty() {
            continue;
        }
        let m = r.len() as Real;
        let l: Vec<(u32, Real)> = std::iter::once((v as u32, 1.0))
            .chain(r.iter().map(|&u| (u, -1.0 / m)))
            .collect();
        for &(a, x) in &l {
            for &(b, y) in &l {
                *rows[a as usize].entry(b).or_default() += w[v] * x * y;
            }
        }
    }
    let rows: Vec<Vec<(u32, Real)>> = rows.into_iter().map(|r| r.into_iter().collect()).collect();
    StencilTable::from_rows(n, &rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Point3;

    #[test]
    fn umbrella_energy_is_zero_on_an_affine_grid_interior_and_positive_on_a_spike() {
        let cube = crate::examples::cube();
        let ring = vertex_rings(&cube);
        assert!(ring.iter().all(|r| r.len() == 3));
        let u = umbrella_matrix(&ring, &[1.0; 8]);
        let energy = |p: &[Point3]| -> Real {
            u.apply(p)
                .unwrap()
                .iter()
                .zip(p)
                .map(|(a, b)| a.coords.dot(&b.coords))
                .sum()
        };
        // A translation costs nothing (the rows sum to zero) ...
        let moved: Vec<Point3> = cube
            .positions
            .iter()
            .map(|p| p + crate::math::Vector3::new(3.0, -1.0, 2.0))
            .collect();
        let e0 = energy(&cube.positions);
        assert!((energy(&moved) - e0).abs() < 1e-9 * e0.max(1.0));
        // ... and pulling one corner out costs more.
        let mut spike = cube.positions.clone();
        spike[0] = Point3::new(-3.0, -3.0, -3.0);
        assert!(energy(&spike) > e0 + 1.0);
        // Zero weights leave the energy out.
        let none = umbrella_matrix(&ring, &[0.0; 8]);
        assert!(
            none.apply(&spike)
                .unwrap()
                .iter()
                .all(|p| p.coords.norm() == 0.0)
        );
    }
}

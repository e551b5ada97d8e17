//! The boundary quads of a voxel set ("cuberille" surface) and Taubin λ|μ
//! smoothing of the resulting cage.

use super::voxels::VoxelGrid;
use crate::error::Result;
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;

/// One quad per face between a solid voxel and an empty one (voxels outside
/// the grid are empty), counter-clockwise seen from the empty side, so
/// normals point out of the solid. Lattice corners are shared, which merges
/// coincident vertices; `corner` maps lattice coordinates to positions.
pub fn boundary_quads(grid: &VoxelGrid, corner: impl Fn([usize; 3]) -> Point3) -> Result<PolyMesh> {
    let [d0, d1, _] = grid.dims;
    let lattice =
        |c: [isize; 3]| c[0] as usize + (d0 + 1) * (c[1] as usize + (d1 + 1) * c[2] as usize);
    let mut id: std::collections::HashMap<usize, u32> = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for n in 0..grid.solid.len() {
        if !grid.solid[n] {
            continue;
        }
        let v = grid.coords(n);
        for a in 0..3 {
            for positive in [true, false] {
                let mut w = v;
                w[a] += if positive { 1 } else { -1 };
                if grid.get(w) {
                    continue;
                }
                let (a1, a2) = ((a + 1) % 3, (a + 2) % 3);
                let mut base = v;
                if positive {
                    base[a] += 1;
                }
                let step = |c: [isize; 3], axis: usize| {
                    let mut c = c;
                    c[axis] += 1;
                    c
                };
                let c0 = base;
                let c1 = step(base, a1);
                let c2 = step(c1, a2);
                let c3 = step(base, a2);
                let ring = if positive {
                    [c0, c1, c2, c3]
                } else {
                    [c0, c3, c2, c1]
                };
                let face: Vec<u32> = ring
                    .iter()
                    .map(|&c| {
                        *id.entry(lattice(c)).or_insert_with(|| {
                            positions.push(corner([c[0] as usize, c[1] as usize, c[2] as usize]));
                            (positions.len() - 1) as u32
                        })
                    })
                    .collect();
                faces.push(face);
            }
        }
    }
    PolyMesh::from_faces(positions, &faces)
}

/// Taubin smoothing (Taubin 1995, "A signal processing approach to fair
/// surface design"): `steps` pairs of umbrella steps `p ← p + λ Δp` then
/// `p ← p + μ Δp` with `Δp = mean(neighbours) − p`, `λ = 0.5`, `μ = −0.53`;
/// the negative step undoes the shrinkage of plain Laplacian smoothing, so the
/// cage loses its staircase but keeps its size.
pub fn taubin_smoothed(mesh: &PolyMesh, steps: usize) -> PolyMesh {
    taubin_smoothed_where(mesh, steps, &vec![true; mesh.num_vertices()])
}

/// [`taubin_smoothed`] moving only the vertices `v` with `moving[v]` (the
/// others stay, and their neighbours still see them).
pub fn taubin_smoothed_where(mesh: &PolyMesh, steps: usize, moving: &[bool]) -> PolyMesh {
    const LAMBDA: Real = 0.5;
    const MU: Real = -0.53;
    let nv = mesh.num_vertices();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for f in mesh.faces() {
        for (k, &a) in f.iter().enumerate() {
            let b = f[(k + 1) % f.len()];
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let mut p = mesh.positions.clone();
    for _ in 0..steps {
        for factor in [LAMBDA, MU] {
            let delta: Vec<Vector3> = (0..nv)
                .map(|v| {
                    let list = &neighbours[v];
                    if list.is_empty() {
                        return Vector3::zeros();
                    }
                    let mean = list.iter().map(|&u| p[u as usize].coords).sum::<Vector3>()
                        / list.len() as Real;
                    mean - p[v].coords
                })
                .collect();
            for ((q, d), _) in p.iter_mut().zip(&delta).zip(moving).filter(|(_, m)| **m) {
                *q += d * factor;
            }
        }
    }
    PolyMesh {
        positions: p,
        face_offsets: mesh.face_offsets.clone(),
        face_vertices: mesh.face_vertices.clone(),
    }
}

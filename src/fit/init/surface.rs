//! Checks on a finished cage: manifold connectivity, Euler characteristic,
//! genus, boundary loops and the signed volume used to confirm orientation.

use crate::error::{Error, Result};
use crate::math::{Real, Vector3};
use crate::mesh::PolyMesh;
use crate::topology::{Level, UnionFind};

/// Topological summary of a manifold mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceTopology {
    /// Connected components (through edges).
    pub components: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// Euler characteristic `χ = V − E + F` (isolated vertices excluded).
    pub euler: i64,
    /// Total genus `g = (2c − b − χ) / 2`.
    pub genus: i64,
}

/// Builds the mesh's [`Level`] (which rejects non-manifold edges and vertices
/// and inconsistent orientation) and counts components, boundary loops and genus.
pub fn surface_topology(mesh: &PolyMesh) -> Result<SurfaceTopology> {
    let level = Level::from_mesh(mesh)?;
    let nf = level.num_faces();
    // Components by union-find over faces that share an edge.
    let mut sets = UnionFind::new(nf);
    let mut boundary_edges = Vec::new();
    for (e, faces) in level.edge_faces.iter().enumerate() {
        if level.is_boundary_edge(e) {
            boundary_edges.push(e);
            continue;
        }
        sets.union(faces[0] as usize, faces[1] as usize);
    }
    let components = (0..nf).filter(|&f| sets.find(f) == f).count();
    // Boundary loops: each boundary vertex of a manifold mesh has exactly two
    // boundary edges, so loops are components of the boundary-edge graph.
    let nv = level.num_vertices;
    let mut loops = UnionFind::new(nv);
    let mut on_boundary = vec![false; nv];
    for &e in &boundary_edges {
        let [v0, v1] = level.edge_verts[e];
        on_boundary[v0 as usize] = true;
        on_boundary[v1 as usize] = true;
        loops.union(v0 as usize, v1 as usize);
    }
    let boundary_loops = (0..nv)
        .filter(|&v| on_boundary[v] && loops.find(v) == v)
        .count();
    let used = (0..nv).filter(|&v| level.valence(v) > 0).count() as i64;
    let euler = used - level.num_edges() as i64 + nf as i64;
    let twice = 2 * components as i64 - boundary_loops as i64 - euler;
    if twice < 0 || twice % 2 != 0 {
        return Err(Error::Topology(format!(
            "inconsistent Euler characteristic {euler} for {components} components and \
             {boundary_loops} boundary loops"
        )));
    }
    Ok(SurfaceTopology {
        components,
        boundary_loops,
        euler,
        genus: twice / 2,
    })
}

/// Signed volume `V = 1/6 Σ_faces Σ_fan p_0 · (p_i × p_{i+1})`; positive for
/// a closed mesh whose faces are counter-clockwise seen from outside.
pub fn signed_volume(mesh: &PolyMesh) -> Real {
    mesh.faces()
        .map(|f| {
            let p0: Vector3 = mesh.positions[f[0] as usize].coords;
            f.windows(2)
                .skip(1)
                .map(|w| {
                    let (a, b) = (
                        mesh.positions[w[0] as usize].coords,
                        mesh.positions[w[1] as usize].coords,
                    );
                    p0.dot(&a.cross(&b))
                })
                .sum::<Real>()
        })
        .sum::<Real>()
        / 6.0
}

/// Reverses every face's vertex order (flips all normals).
pub fn reversed(mesh: &PolyMesh) -> Result<PolyMesh> {
    let faces: Vec<Vec<u32>> = mesh
        .faces()
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    PolyMesh::from_faces(mesh.positions.clone(), &faces)
}

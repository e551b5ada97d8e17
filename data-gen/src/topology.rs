//! `mesh_topology`: closedness, manifoldness, orientation, Euler
//! characteristic and genus of a polygon mesh — the checks every generated
//! ground truth must pass.

use std::collections::HashMap;

use serde::Serialize;
use subdyn::mesh::PolyMesh;

/// What [`mesh_topology`] found.
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
pub struct MeshTopology {
    /// Number of vertices `V` (isolated vertices included).
    pub vertices: usize,
    /// Number of undirected edges `E`.
    pub edges: usize,
    /// Number of faces `F`.
    pub faces: usize,
    /// `V − E + F`.
    pub euler_characteristic: i64,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with three or more faces.
    pub non_manifold_edges: usize,
    /// Edges used twice in the same direction (the two faces disagree on orientation).
    pub misoriented_edges: usize,
    /// Vertices whose faces do not form a single fan.
    pub non_manifold_vertices: usize,
    /// Vertices in no face.
    pub isolated_vertices: usize,
    /// Connected components (of the faces).
    pub components: usize,
    /// Every edge has exactly two faces.
    pub closed: bool,
    /// Closed, edge- and vertex-manifold, consistently oriented, no isolated vertices.
    pub closed_manifold: bool,
    /// `g = (2 − χ) / 2` for a closed manifold with one component, else `None`.
    pub genus: Option<i64>,
}

/// Counts vertices, edges and faces and checks that `mesh` is a closed,
/// oriented 2-manifold; the genus follows from `χ = V − E + F = 2 − 2g`.
pub fn mesh_topology(mesh: &PolyMesh) -> MeshTopology {
    let nv = mesh.num_vertices();
    // Directed edge (a, b) -> number of uses.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for face in mesh.faces() {
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            *directed.entry((a, b)).or_insert(0) += 1;
        }
    }
    let mut undirected: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    for (&(a, b), &n) in &directed {
        let entry = undirected.entry((a.min(b), a.max(b))).or_insert((0, 0));
        if a < b {
            entry.0 += n;
        } else {
            entry.1 += n;
        }
    }
    let mut boundary_edges = 0;
    let mut non_manifold_edges = 0;
    let mut misoriented_edges = 0;
    for &(forward, backward) in undirected.values() {
        match forward + backward {
            1 => boundary_edges += 1,
            2 => {}
            _ => non_manifold_edges += 1,
        }
        if forward > 1 || backward > 1 {
            misoriented_edges += 1;
        }
    }

    let mut used = vec![false; nv];
    for &v in &mesh.face_vertices {
        used[v as usize] = true;
    }
    let isolated_vertices = used.iter().filter(|&&u| !u).count();
    let non_manifold_vertices = non_manifold_vertices(mesh);
    let components = components(mesh);

    let edges = undirected.len();
    let euler_characteristic = nv as i64 - edges as i64 + mesh.num_faces() as i64;
    let closed = boundary_edges == 0 && non_manifold_edges == 0;
    let closed_manifold =
        closed && misoriented_edges == 0 && non_manifold_vertices == 0 && isolated_vertices == 0;
    let genus = (closed_manifold && components == 1).then(|| (2 - euler_characteristic) / 2);
    MeshTopology {
        vertices: nv,
        edges,
        faces: mesh.num_faces(),
        euler_characteristic,
        boundary_edges,
        non_manifold_edges,
        misoriented_edges,
        non_manifold_vertices,
        isolated_vertices,
        components,
        closed,
        closed_manifold,
        genus,
    }
}

/// Vertices whose corners do not chain into one cycle (or one open fan).
///
/// Each face corner at `v` is a wedge `prev → v → next`; the wedge across the
/// edge `v–next` is the one whose `prev` is `next`. A manifold vertex's wedges
/// form a single chain.
fn non_manifold_vertices(mesh: &PolyMesh) -> usize {
    let nv = mesh.num_vertices();
    let mut wedges: Vec<Vec<(u32, u32)>> = vec![Vec::new(); nv];
    for face in mesh.faces() {
        let n = face.len();
        for i in 0..n {
            wedges[face[i] as usize].push((face[(i + n - 1) % n], face[(i + 1) % n]));
        }
    }
    let mut bad = 0;
    for ws in &wedges {
        if ws.is_empty() {
            continue;
        }
        let by_prev: HashMap<u32, usize> = ws.iter().enumerate().map(|(i, w)| (w.0, i)).collect();
        if by_prev.len() != ws.len() {
            bad += 1;
            continue;
        }
        // Start from a wedge nobody leads into (an open fan), else anywhere.
        let nexts: std::collections::HashSet<u32> = ws.iter().map(|w| w.1).collect();
        let start = ws.iter().position(|w| !nexts.contains(&w.0)).unwrap_or(0);
        let mut seen = 1;
        let mut at = start;
        while let Some(&next) = by_prev.get(&ws[at].1) {
            if next == start || seen > ws.len() {
                break;
            }
            at = next;
            seen += 1;
        }
        if seen != ws.len() {
            bad += 1;
        }
    }
    bad
}

/// Connected components of the faces (union-find over face vertices).
fn components(mesh: &PolyMesh) -> usize {
    let nv = mesh.num_vertices();
    let mut parent: Vec<u32> = (0..nv as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for face in mesh.faces() {
        let a = find(&mut parent, face[0]);
        for &v in &face[1..] {
            let b = find(&mut parent, v);
            if a != b {
                parent[b as usize] = a;
            }
        }
    }
    let mut roots = std::collections::HashSet::new();
    for face in mesh.faces() {
        roots.insert(find(&mut parent, face[0]));
    }
    roots.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_is_a_sphere() {
        let t = mesh_topology(&subdyn::examples::cube());
        assert_eq!((t.vertices, t.edges, t.faces), (8, 12, 6));
        assert_eq!(t.euler_characteristic, 2);
        assert!(t.closed_manifold);
        assert_eq!(t.genus, Some(0));
    }

    #[test]
    fn torus_has_genus_one() {
        let t = mesh_topology(&subdyn::examples::torus(8, 6, 2.0, 0.5));
        assert_eq!(t.euler_characteristic, 0);
        assert_eq!(t.genus, Some(1));
    }

    #[test]
    fn open_and_misoriented_meshes_are_caught() {
        let cube = subdyn::examples::cube();
        let faces: Vec<Vec<u32>> = cube.faces().skip(1).map(|f| f.to_vec()).collect();
        let open = PolyMesh::from_faces(cube.positions.clone(), &faces).unwrap();
        let t = mesh_topology(&open);
        assert_eq!(t.boundary_edges, 4);
        assert!(!t.closed && t.genus.is_none());

        let mut faces: Vec<Vec<u32>> = cube.faces().map(|f| f.to_vec()).collect();
        faces[0].reverse();
        let flipped = PolyMesh::from_faces(cube.positions.clone(), &faces).unwrap();
        let t = mesh_topology(&flipped);
        assert!(t.closed && !t.closed_manifold);
        assert_eq!(t.misoriented_edges, 4);
    }
}

//! `MeshStats`: counts, boundaries, components, Euler characteristic and
//! genus of any polygon mesh — also of one that cannot be subdivided
//! (non-manifold edges are counted, not rejected), so `info` can describe it.

use std::collections::BTreeMap;

use subdyn::mesh::PolyMesh;
use subdyn::topology::{Level, UnionFind};

/// One connected component (faces joined through shared vertices).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ComponentStats {
    /// Vertices of the component.
    pub vertices: usize,
    /// Edges of the component.
    pub edges: usize,
    /// Faces of the component.
    pub faces: usize,
    /// Edges with a single face.
    pub boundary_edges: usize,
    /// Closed chains of boundary edges.
    pub boundary_loops: usize,
    /// χ = V − E + F.
    pub euler: i64,
    /// Genus `(2 − χ) / 2`, for a closed, manifold, consistently oriented component.
    pub genus: Option<i64>,
}

/// Statistics of a polygon mesh.
#[derive(Clone, Debug, Default)]
pub struct MeshStats {
    /// All vertices, isolated ones included.
    pub vertices: usize,
    /// Faces.
    pub faces: usize,
    /// Distinct edges (vertex pairs joined by a face side).
    pub edges: usize,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Closed chains of boundary edges.
    pub boundary_loops: usize,
    /// Face size → number of faces.
    pub face_sizes: BTreeMap<usize, usize>,
    /// Valence (edges at a vertex) → number of vertices, isolated vertices excluded.
    pub valences: BTreeMap<usize, usize>,
    /// Vertices in no face.
    pub isolated_vertices: usize,
    /// Connected components, largest first.
    pub components: Vec<ComponentStats>,
    /// Why subdyn cannot subdivide the mesh; `None` when it can.
    pub problem: Option<String>,
}

impl MeshStats {
    /// Euler characteristic of the surface (isolated vertices not counted).
    pub fn euler(&self) -> i64 {
        self.components.iter().map(|c| c.euler).sum()
    }
}

/// Computes the statistics of `mesh` (whose face indices must be in range).
pub fn mesh_stats(mesh: &PolyMesh) -> MeshStats {
    let nv = mesh.num_vertices();
    let mut face_sizes = BTreeMap::new();
    let mut faces_uf = UnionFind::new(nv);
    let mut used = vec![false; nv];
    for f in mesh.faces() {
        *face_sizes.entry(f.len()).or_insert(0) += 1;
        for &v in f {
            used[v as usize] = true;
            faces_uf.union(f[0] as usize, v as usize);
        }
    }
    let edges = edges_with_counts(mesh);
    let mut valence = vec![0usize; nv];
    let mut boundary_uf = UnionFind::new(nv);
    let mut on_boundary = vec![false; nv];
    let mut stats = MeshStats {
        vertices: nv,
        faces: mesh.num_faces(),
        edges: edges.len(),
        face_sizes,
        ..Default::default()
    };
    for &(a, b, count) in &edges {
        valence[a as usize] += 1;
        valence[b as usize] += 1;
        if count == 1 {
            stats.boundary_edges += 1;
            boundary_uf.union(a as usize, b as usize);
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        } else if count > 2 {
            stats.non_manifold_edges += 1;
        }
    }
    for v in 0..nv {
        if used[v] {
            *stats.valences.entry(valence[v]).or_insert(0) += 1;
        } else {
            stats.isolated_vertices += 1;
        }
    }

    // Components, keyed by their union-find root.
    let mut index: BTreeMap<usize, usize> = BTreeMap::new();
    let mut comps: Vec<ComponentStats> = Vec::new();
    let mut comp_of = |root: usize, comps: &mut Vec<ComponentStats>| -> usize {
        *index.entry(root).or_insert_with(|| {
            comps.push(ComponentStats::default());
            comps.len() - 1
        })
    };
    for v in (0..nv).filter(|&v| used[v]) {
        let c = comp_of(faces_uf.find(v), &mut comps);
        comps[c].vertices += 1;
    }
    for f in mesh.faces() {
        let c = comp_of(faces_uf.find(f[0] as usize), &mut comps);
        comps[c].faces += 1;
    }
    for &(a, _, count) in &edges {
        let c = comp_of(faces_uf.find(a as usize), &mut comps);
        comps[c].edges += 1;
        if count == 1 {
            comps[c].boundary_edges += 1;
        }
    }
    let mut loop_roots: Vec<usize> = (0..nv)
        .filter(|&v| on_boundary[v])
        .map(|v| boundary_uf.find(v))
        .collect();
    loop_roots.sort_unstable();
    loop_roots.dedup();
    stats.boundary_loops = loop_roots.len();
    for root in loop_roots {
        let c = comp_of(faces_uf.find(root), &mut comps);
        comps[c].boundary_loops += 1;
    }

    stats.problem = Level::from_mesh(mesh).err().map(|e| e.to_string());
    let manifold = stats.problem.is_none();
    for c in &mut comps {
        c.euler = c.vertices as i64 - c.edges as i64 + c.faces as i64;
        if manifold && c.boundary_edges == 0 && c.euler <= 2 && c.euler % 2 == 0 {
            c.genus = Some((2 - c.euler) / 2);
        }
    }
    comps.sort_by(|a, b| b.faces.cmp(&a.faces).then(b.vertices.cmp(&a.vertices)));
    stats.components = comps;
    stats
}

/// Distinct edges `(a, b, faces)` with `a < b` and the number of faces using them.
fn edges_with_counts(mesh: &PolyMesh) -> Vec<(u32, u32, usize)> {
    let mut keys: Vec<u64> = Vec::with_capacity(mesh.face_vertices.len());
    for f in mesh.faces() {
        for (i, &a) in f.iter().enumerate() {
            let b = f[(i + 1) % f.len()];
            keys.push(((a.min(b) as u64) << 32) | a.max(b) as u64);
        }
    }
    keys.sort_unstable();
    let mut out: Vec<(u32, u32, usize)> = Vec::new();
    for k in keys {
        let (a, b) = ((k >> 32) as u32, k as u32);
        match out.last_mut() {
            Some(last) if last.0 == a && last.1 == b => last.2 += 1,
            _ => out.push((a, b, 1)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use subdyn::math::Point3;

    #[test]
    fn cube_is_one_closed_genus_zero_component() {
        let s = mesh_stats(&subdyn::examples::cube());
        assert_eq!((s.vertices, s.edges, s.faces), (8, 12, 6));
        assert_eq!(s.components.len(), 1);
        assert_eq!(s.euler(), 2);
        assert_eq!(s.components[0].genus, Some(0));
        assert_eq!(s.valences.get(&3), Some(&8));
        assert_eq!(s.boundary_loops, 0);
    }

    #[test]
    fn torus_has_genus_one() {
        let s = mesh_stats(&subdyn::examples::torus(6, 5, 1.0, 0.3));
        assert_eq!(s.euler(), 0);
        assert_eq!(s.components[0].genus, Some(1));
        assert_eq!(s.valences.get(&4), Some(&30));
    }

    #[test]
    fn open_grid_has_one_boundary_loop_and_no_genus() {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let pos = vec![
            p(0., 0.),
            p(1., 0.),
            p(2., 0.),
            p(0., 1.),
            p(1., 1.),
            p(2., 1.),
            p(5., 5.),
        ];
        let mesh = PolyMesh::from_faces(pos, &[vec![0, 1, 4, 3], vec![1, 2, 5, 4]]).unwrap();
        let s = mesh_stats(&mesh);
        assert_eq!((s.edges, s.boundary_edges, s.boundary_loops), (7, 6, 1));
        assert_eq!(s.isolated_vertices, 1);
        assert_eq!(s.components[0].genus, None);
        assert_eq!(s.euler(), 1);
    }

    #[test]
    fn non_manifold_edge_is_counted_not_rejected() {
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let pos = vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(0., 1., 0.),
            p(0., -1., 0.),
            p(0., 0., 1.),
        ];
        let mesh =
            PolyMesh::from_faces(pos, &[vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]]).unwrap();
        let s = mesh_stats(&mesh);
        assert_eq!(s.non_manifold_edges, 1);
        assert!(s.problem.is_some());
    }
}

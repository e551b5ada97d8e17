//! `Level`: the connectivity of one subdivision level (no positions).
//!
//! Faces are stored in CSR form with a parallel array of face edges: edge `i`
//! of face `f` joins face vertex `i` to face vertex `i + 1`. Every edge knows
//! its two end vertices and at most two faces (manifold meshes only); every
//! vertex knows its incident faces and edges (unordered; use
//! [`Level::vertex_ring`] for the cyclic order).

use crate::error::{Error, Result};
use crate::math::{group_by_key, u32_offsets};
use crate::mesh::PolyMesh;

/// Marker for "no face" in [`Level::edge_faces`].
pub const NONE: u32 = u32::MAX;

/// Connectivity of one level of a subdivision hierarchy.
#[derive(Clone, Debug, Default)]
pub struct Level {
    /// Number of vertices (including isolated ones).
    pub num_vertices: usize,
    /// `num_faces + 1` offsets into `face_verts` and `face_edges`.
    pub face_offsets: Vec<u32>,
    /// Vertices of each face, counter-clockwise.
    pub face_verts: Vec<u32>,
    /// Edges of each face: entry `k` joins `face_verts[k]` and the next vertex of the face.
    pub face_edges: Vec<u32>,
    /// End vertices of each edge.
    pub edge_verts: Vec<[u32; 2]>,
    /// The one or two faces of each edge; the second is [`NONE`] on a boundary.
    pub edge_faces: Vec<[u32; 2]>,
    /// `num_vertices + 1` offsets into `vert_faces`.
    pub vert_face_offsets: Vec<u32>,
    /// Faces incident to each vertex (unordered).
    pub vert_faces: Vec<u32>,
    /// `num_vertices + 1` offsets into `vert_edges`.
    pub vert_edge_offsets: Vec<u32>,
    /// Edges incident to each vertex (unordered).
    pub vert_edges: Vec<u32>,
}

/// A vertex's faces and edges in cyclic order.
///
/// For an interior vertex of valence `n`: `edges[i]` and `edges[i + 1]` are
/// the edges of `faces[i]` at the vertex (indices mod `n`). For a boundary
/// vertex there is one more edge than faces: the walk starts at a boundary edge
/// (`edges[0]`) and ends at the other (`edges[n_faces]`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VertexRing {
    /// Incident faces in order.
    pub faces: Vec<u32>,
    /// Incident edges in order.
    pub edges: Vec<u32>,
    /// True when the vertex lies on the mesh boundary.
    pub boundary: bool,
}

impl Level {
    /// Builds level 0 from a mesh: creates edges, checks that the mesh can be
    /// subdivided and reports the first problem as [`Error::Topology`] naming
    /// the element (non-manifold edge or vertex, repeated vertex in a face,
    /// inconsistent orientation, index out of range).
    pub fn from_mesh(mesh: &PolyMesh) -> Result<Level> {
        mesh.validate()?;
        let level = Self::from_faces(mesh.num_vertices(), &mesh.face_offsets, &mesh.face_vertices)?;
        level.check_manifold_vertices()?;
        Ok(level)
    }

    /// Builds a level from raw faces without the non-manifold-vertex check
    /// (used for local patches cut out of a larger mesh, whose rim vertices
    /// may look like bow-ties). Indices must be in range.
    pub fn from_faces(nv: usize, face_offsets: &[u32], face_vertices: &[u32]) -> Result<Level> {
        let mesh = FaceList {
            face_offsets,
            face_vertices,
        };
        for (f, face) in mesh.faces().enumerate() {
            for (i, &a) in face.iter().enumerate() {
                if face[i + 1..].contains(&a) {
                    return Err(Error::Topology(format!(
                        "face {f} is degenerate: vertex {a} appears twice"
                    )));
                }
            }
        }
        // Half-edges keyed by (min, max) vertex, sorted to find edge partners.
        let nh = mesh.face_vertices.len();
        let mut half: Vec<(u64, u32)> = Vec::with_capacity(nh);
        for f in 0..mesh.num_faces() {
            let (a, b) = (
                mesh.face_offsets[f] as usize,
                mesh.face_offsets[f + 1] as usize,
            );
            for k in a..b {
                let v0 = mesh.face_vertices[k];
                let v1 = mesh.face_vertices[if k + 1 == b { a } else { k + 1 }];
                let key = ((v0.min(v1) as u64) << 32) | v0.max(v1) as u64;
                half.push((key, k as u32));
            }
        }
        half.sort_unstable();
        let face_of = face_of_corner(mesh.face_offsets);
        let mut face_edges = vec![0u32; nh];
        let mut edge_verts = Vec::with_capacity(nh / 2 + 1);
        let mut edge_faces = Vec::with_capacity(nh / 2 + 1);
        let mut i = 0;
        while i < half.len() {
            let mut j = i + 1;
            while j < half.len() && half[j].0 == half[i].0 {
                j += 1;
            }
            let (v0, v1) = ((half[i].0 >> 32) as u32, half[i].0 as u32);
            if j - i > 2 {
                let faces: Vec<u32> = half[i..j].iter().map(|h| face_of[h.1 as usize]).collect();
                return Err(Error::Topology(format!(
                    "non-manifold edge ({v0}, {v1}) is shared by {} faces {faces:?}; at most two allowed",
                    j - i
                )));
            }
            let e = edge_verts.len() as u32;
            let k0 = half[i].1 as usize;
            let f0 = face_of[k0];
            let mut faces = [f0, NONE];
            face_edges[k0] = e;
            if j - i == 2 {
                let k1 = half[i + 1].1 as usize;
                let f1 = face_of[k1];
                if mesh.face_vertices[k0] == mesh.face_vertices[k1] {
                    return Err(Error::Topology(format!(
                        "faces {f0} and {f1} have opposite orientations across edge ({v0}, {v1}); \
                         make the faces' vertex order consistent"
                    )));
                }
                faces[1] = f1;
                face_edges[k1] = e;
            }
            // Store the edge in the direction of its first face.
            let first = mesh.face_vertices[k0];
            edge_verts.push(if first == v0 { [v0, v1] } else { [v1, v0] });
            edge_faces.push(faces);
            i = j;
        }
        let mut level = Level {
            num_vertices: nv,
            face_offsets: face_offsets.to_vec(),
            face_verts: face_vertices.to_vec(),
            face_edges,
            edge_verts,
            edge_faces,
            ..Default::default()
        };
        level.build_vertex_adjacency();
        Ok(level)
    }

    /// Fills `vert_faces` and `vert_edges` from faces and edges (counting sort).
    pub fn build_vertex_adjacency(&mut self) {
        let nv = self.num_vertices;
        let faces = (0..self.num_faces()).flat_map(|f| {
            self.face_vertices(f)
                .iter()
                .map(move |&v| (v as usize, f as u32))
        });
        let (offs, items) = group_by_key(nv, faces);
        self.vert_face_offsets = u32_offsets(offs);
        self.vert_faces = items;
        let edges = (self.edge_verts.iter().enumerate())
            .flat_map(|(e, ev)| ev.map(|v| (v as usize, e as u32)));
        let (offs, items) = group_by_key(nv, edges);
        self.vert_edge_offsets = u32_offsets(offs);
        self.vert_edges = items;
    }

    fn check_manifold_vertices(&self) -> Result<()> {
        for v in 0..self.num_vertices {
            let nf = self.vertex_faces(v).len();
            if nf == 0 {
                continue;
            }
            let ring = self.vertex_ring(v);
            let boundary_edges = self
                .vertex_edges(v)
                .iter()
                .filter(|&&e| self.is_boundary_edge(e as usize))
                .count();
            if ring.faces.len() != nf || boundary_edges > 2 {
                return Err(Error::Topology(format!(
                    "non-manifold vertex {v}: its {nf} faces form more than one fan"
                )));
            }
        }
        Ok(())
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }

    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.edge_verts.len()
    }

    /// Vertices of face `f`.
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        &self.face_verts[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Edges of face `f` (edge `i` joins vertex `i` and `i + 1`).
    pub fn face_edge_list(&self, f: usize) -> &[u32] {
        &self.face_edges[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Faces incident to vertex `v` (unordered).
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        &self.vert_faces[self.vert_face_offsets[v] as usize..self.vert_face_offsets[v + 1] as usize]
    }

    /// Edges incident to vertex `v` (unordered).
    pub fn vertex_edges(&self, v: usize) -> &[u32] {
        &self.vert_edges[self.vert_edge_offsets[v] as usize..self.vert_edge_offsets[v + 1] as usize]
    }

    /// Number of edges at vertex `v`.
    pub fn valence(&self, v: usize) -> usize {
        self.vertex_edges(v).len()
    }

    /// True when edge `e` has only one face.
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces[e][1] == NONE
    }

    /// True when vertex `v` lies on a boundary edge.
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        self.vertex_edges(v)
            .iter()
            .any(|&e| self.is_boundary_edge(e as usize))
    }

    /// The vertex at the other end of edge `e` from `v`.
    pub fn other_vertex(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.edge_verts[e];
        if a == v { b } else { a }
    }

    /// Position of vertex `v` within face `f`, if present.
    pub fn corner_in_face(&self, f: usize, v: u32) -> Option<usize> {
        self.face_vertices(f).iter().position(|&x| x == v)
    }

    /// Faces and edges around `v` in counter-clockwise order (see [`VertexRing`]).
    pub fn vertex_ring(&self, v: usize) -> VertexRing {
        let vf = self.vertex_faces(v);
        if vf.is_empty() {
            return VertexRing::default();
        }
        let v32 = v as u32;
        // In face f with v at corner i, the leading edge is edge i (v -> next)
        // and the trailing edge is edge i-1 (prev -> v). Walking counter-clockwise
        // around v goes from a face to the neighbour across its trailing edge...
        // we walk so that edges[k] is the leading edge of faces[k].
        let lead_trail = |f: u32| -> (u32, u32) {
            let fe = self.face_edge_list(f as usize);
            let i = self.corner_in_face(f as usize, v32).unwrap_or(0);
            (fe[i], fe[(i + fe.len() - 1) % fe.len()])
        };
        let across = |e: u32, f: u32| -> u32 {
            let [a, b] = self.edge_faces[e as usize];
            if a == f { b } else { a }
        };
        // Find a start: for a boundary vertex, the face whose leading edge is a boundary edge.
        let mut start = vf[0];
        let mut boundary = false;
        for &f in vf {
            let (lead, _) = lead_trail(f);
            if self.is_boundary_edge(lead as usize) {
                start = f;
                boundary = true;
                break;
            }
        }
        let mut faces = Vec::with_capacity(vf.len());
        let mut edges = Vec::with_capacity(vf.len() + 1);
        let mut f = start;
        loop {
            let (lead, trail) = lead_trail(f);
            faces.push(f);
            edges.push(lead);
            let next = across(trail, f);
            if next == NONE {
                edges.push(trail);
                break;
            }
            if next == start || faces.len() > vf.len() {
                break;
            }
            f = next;
        }
        VertexRing {
            faces,
            edges,
            boundary,
        }
    }
}

/// Borrowed CSR faces.
struct FaceList<'a> {
    face_offsets: &'a [u32],
    face_vertices: &'a [u32],
}

impl FaceList<'_> {
    fn num_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }
    fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.num_faces()).map(|f| {
            &self.face_vertices[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
        })
    }
}

/// For every face corner (index into `face_verts`), the face it belongs to.
pub fn face_of_corner(face_offsets: &[u32]) -> Vec<u32> {
    let mut out = vec![0u32; face_offsets.last().copied().unwrap_or(0) as usize];
    for f in 0..face_offsets.len().saturating_sub(1) {
        out[face_offsets[f] as usize..face_offsets[f + 1] as usize].fill(f as u32);
    }
    out
}

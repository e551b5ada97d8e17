//! `LatticeTopology`: vertices, edges, faces and cells of a volume lattice of
//! arbitrary topology (no positions), with the adjacency the Catmull-Clark
//! volume rules need (MacCracken & Joy 1996, §2.2).
//!
//! Faces are vertex loops; cells are lists of faces. Edges and every
//! incidence relation are derived once when the topology is built, and the
//! topological checks (closed cells, at most two cells per face, no repeated
//! faces, connectedness) run there, each naming the failing element.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::math::{group_by_key, u32_offsets};

/// Marker for "no cell" in [`LatticeTopology::face_cells`].
pub const NO_CELL: u32 = u32::MAX;

/// A compressed-row list of lists of `u32`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Csr {
    /// `len + 1` offsets into `items`.
    pub offsets: Vec<u32>,
    /// The concatenated lists.
    pub items: Vec<u32>,
}

impl Csr {
    /// Builds from a list of lists.
    pub fn from_lists<L: AsRef<[u32]>>(lists: &[L]) -> Csr {
        let mut c = Csr {
            offsets: Vec::with_capacity(lists.len() + 1),
            items: Vec::new(),
        };
        c.offsets.push(0);
        for l in lists {
            c.items.extend_from_slice(l.as_ref());
            c.offsets.push(c.items.len() as u32);
        }
        c
    }

    /// Groups `(row, item)` pairs into `rows` lists (items in pair order).
    pub fn from_pairs(rows: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Csr {
        let (offsets, items) = group_by_key(rows, pairs.map(|(r, x)| (r as usize, x)));
        let offsets = u32_offsets(offsets);
        Csr { offsets, items }
    }

    /// Number of lists.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True when there is no list.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// List `i`.
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Bytes held by the two arrays.
    pub fn bytes(&self) -> usize {
        4 * (self.offsets.len() + self.items.len())
    }
}

/// The topology of a volume lattice: faces as vertex loops, cells as face
/// lists, and the derived edges and incidences.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LatticeTopology {
    /// Number of vertices.
    pub num_vertices: usize,
    /// Vertex loop of every face.
    pub faces: Csr,
    /// Faces of every cell.
    pub cells: Csr,
    /// Edges as `[a, b]` with `a < b`.
    pub edges: Vec<[u32; 2]>,
    /// Edge `i` of a face joins its vertices `i` and `i + 1` (same layout as `faces`).
    pub face_edges: Csr,
    /// The one or two cells of every face ([`NO_CELL`] in the second slot for a boundary face).
    pub face_cells: Vec<[u32; 2]>,
    /// Faces around every edge.
    pub edge_faces: Csr,
    /// Cells around every edge.
    pub edge_cells: Csr,
    /// Distinct vertices of every cell.
    pub cell_vertices: Csr,
    /// Cells around every vertex.
    pub vertex_cells: Csr,
    /// Faces around every vertex.
    pub vertex_faces: Csr,
    /// Edges at every vertex.
    pub vertex_edges: Csr,
}

/// A multiplicative hasher for the integer and short-slice keys of
/// [`LatticeTopology::new`] (the standard SipHash dominated its run time;
/// the keys come from the lattice's own indices, so no flooding defence is
/// needed).
#[derive(Clone, Copy, Default)]
struct FastHash;

struct FastHasher(u64);

impl std::hash::BuildHasher for FastHash {
    type Hasher = FastHasher;
    fn build_hasher(&self) -> FastHasher {
        FastHasher(0)
    }
}

impl std::hash::Hasher for FastHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.write_u64(u64::from_le_bytes(w));
        }
        for &b in chunks.remainder() {
            self.write_u64(b as u64);
        }
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7C_C1_B7_27_22_0A_95);
    }
}

fn edge_key(a: u32, b: u32) -> u64 {
    let (a, b) = if a < b { (a, b) } else { (b, a) };
    ((a as u64) << 32) | b as u64
}

impl LatticeTopology {
    /// Builds and checks a topology from face loops and cells (lists of face
    /// indices). Errors name the face or cell: index out of range, a face
    /// with fewer than three distinct vertices, a repeated face, a face in no
    /// cell or in more than two, a cell that is not closed (an edge of it not
    /// in exactly two of its faces), a cell whose surface is not a sphere,
    /// cells not connected through faces, a vertex in no face.
    pub fn new<F: AsRef<[u32]>, C: AsRef<[u32]>>(
        num_vertices: usize,
        faces: &[F],
        cells: &[C],
    ) -> Result<LatticeTopology> {
        if cells.is_empty() {
            return Err(Error::Topology("the lattice has no cell".into()));
        }
        // Repeated faces: sorted vertex sets in one flat buffer, hashed as
        // slices (no allocation per face).
        let mut keys = Csr::from_lists(faces);
        for (f, loop_) in faces.iter().enumerate() {
            let (a, b) = (keys.offsets[f] as usize, keys.offsets[f + 1] as usize);
            let l = &mut keys.items[a..b];
            if let Some(&v) = l.iter().find(|&&v| v as usize >= num_vertices) {
                return Err(Error::Topology(format!(
                    "face {f}: vertex {v} out of range (the lattice has {num_vertices} vertices)"
                )));
            }
            l.sort_unstable();
            if l.len() < 3 || l.windows(2).any(|w| w[0] == w[1]) {
                return Err(Error::Topology(format!(
                    "face {f}: needs at least three distinct vertices, got {:?}",
                    loop_.as_ref()
                )));
            }
        }
        let mut seen_faces: HashMap<&[u32], usize, FastHash> =
            HashMap::with_capacity_and_hasher(keys.len(), FastHash);
        for f in 0..keys.len() {
            if let Some(g) = seen_faces.insert(keys.row(f), f) {
                return Err(Error::Topology(format!(
                    "face {f} repeats face {g} (same vertices)"
                )));
            }
        }
        drop(seen_faces);
        let faces = Csr::from_lists(faces);
        let cells = Csr::from_lists(cells);
        let nf = faces.len();
        let mut face_cells = vec![[NO_CELL; 2]; nf];
        for c in 0..cells.len() {
            let fs = cells.row(c);
            if fs.len() < 4 {
                return Err(Error::Topology(format!(
                    "cell {c}: has {} faces, a closed cell needs at least 4",
                    fs.len()
                )));
            }
            for &f in fs {
                let slot = face_cells.get_mut(f as usize).ok_or_else(|| {
                    Error::Topology(format!("cell {c}: face {f} out of range ({nf} faces)"))
                })?;
                if slot[0] == c as u32 || slot[1] == c as u32 {
                    return Err(Error::Topology(format!("cell {c}: lists face {f} twice")));
                }
                if slot[0] == NO_CELL {
                    slot[0] = c as u32;
                } else if slot[1] == NO_CELL {
                    slot[1] = c as u32;
                } else {
                    return Err(Error::Topology(format!(
                        "face {f}: belongs to more than two cells ({}, {}, {c})",
                        slot[0], slot[1]
                    )));
                }
            }
        }
        if let Some(f) = face_cells.iter().position(|s| s[0] == NO_CELL) {
            return Err(Error::Topology(format!("face {f}: belongs to no cell")));
        }
        // Edges.
        let mut edge_ids: HashMap<u64, u32, FastHash> =
            HashMap::with_capacity_and_hasher(faces.items.len() / 2, FastHash);
        let mut edges = Vec::new();
        let mut fe = Vec::with_capacity(faces.items.len());
        for f in 0..nf {
            let l = faces.row(f);
            for i in 0..l.len() {
                let (a, b) = (l[i], l[(i + 1) % l.len()]);
                let id = *edge_ids.entry(edge_key(a, b)).or_insert_with(|| {
                    edges.push([a.min(b), a.max(b)]);
                    (edges.len() - 1) as u32
                });
                fe.push(id);
            }
        }
        let face_edges = Csr {
            offsets: faces.offsets.clone(),
            items: fe,
        };
        let ne = edges.len();
        let edge_faces = Csr::from_pairs(
            ne,
            (0..nf).flat_map(|f| face_edges.row(f).iter().map(move |&e| (e, f as u32))),
        );
        // Cell closure: each edge of a cell in exactly two of its faces.
        let mut cell_vertices = Csr {
            offsets: Vec::with_capacity(cells.len() + 1),
            items: Vec::with_capacity(8 * cells.len()),
        };
        cell_vertices.offsets.push(0);
        let mut cell_edges: Vec<u32> = Vec::new();
        for c in 0..cells.len() {
            cell_edges.clear();
            let start = cell_vertices.items.len();
            for &f in cells.row(c) {
                cell_edges.extend_from_slice(face_edges.row(f as usize));
                cell_vertices.items.extend_from_slice(faces.row(f as usize));
            }
            cell_edges.sort_unstable();
            let mut distinct = 0;
            let mut i = 0;
            while i < cell_edges.len() {
                let e = cell_edges[i];
                let k = cell_edges[i..].iter().take_while(|&&x| x == e).count();
                if k != 2 {
                    let [a, b] = edges[e as usize];
                    return Err(Error::Topology(format!(
                        "cell {c}: not closed — edge {a}-{b} is in {k} of its faces (expected 2)"
                    )));
                }
                distinct += 1;
                i += k;
            }
            let verts = &mut cell_vertices.items[start..];
            verts.sort_unstable();
            let mut n = 0;
            for j in 0..verts.len() {
                if j == 0 || verts[j] != verts[n - 1] {
                    verts[n] = verts[j];
                    n += 1;
                }
            }
            cell_vertices.items.truncate(start + n);
            let euler = n as i64 - distinct as i64 + cells.row(c).len() as i64;
            if euler != 2 {
                return Err(Error::Topology(format!(
                    "cell {c}: its faces do not bound a ball (V - E + F = {euler}, expected 2)"
                )));
            }
            cell_vertices.offsets.push(cell_vertices.items.len() as u32);
        }
        let edge_cells = {
            let mut csr = Csr {
                offsets: Vec::with_capacity(ne + 1),
                items: Vec::with_capacity(edge_faces.items.len()),
            };
            csr.offsets.push(0);
            for e in 0..ne {
                let start = csr.items.len();
                for &f in edge_faces.row(e) {
                    for &c in &face_cells[f as usize] {
                        if c != NO_CELL && !csr.items[start..].contains(&c) {
                            csr.items.push(c);
                        }
                    }
                }
                csr.offsets.push(csr.items.len() as u32);
            }
            csr
        };
        let nc = cells.len();
        let vertex_cells = Csr::from_pairs(
            num_vertices,
            (0..nc).flat_map(|c| cell_vertices.row(c).iter().map(move |&v| (v, c as u32))),
        );
        let vertex_faces = Csr::from_pairs(
            num_vertices,
            (0..nf).flat_map(|f| faces.row(f).iter().map(move |&v| (v, f as u32))),
        );
        let vertex_edges = Csr::from_pairs(
            num_vertices,
            edges
                .iter()
                .enumerate()
                .flat_map(|(e, &[a, b])| [(a, e as u32), (b, e as u32)]),
        );
        if let Some(v) = (0..num_vertices).find(|&v| vertex_faces.row(v).is_empty()) {
            return Err(Error::Topology(format!("vertex {v}: belongs to no face")));
        }
        let topo = LatticeTopology {
            num_vertices,
            faces,
            cells,
            edges,
            face_edges,
            face_cells,
            edge_faces,
            edge_cells,
            cell_vertices,
            vertex_cells,
            vertex_faces,
            vertex_edges,
        };
        topo.check_connected()?;
        Ok(topo)
    }

    /// Builds a topology from cells given as polyhedra (each a list of vertex
    /// loops); faces shared by two cells are found by their vertex sets.
    pub fn from_polyhedra(num_vertices: usize, cells: &[Vec<Vec<u32>>]) -> Result<LatticeTopology> {
        let mut ids: HashMap<Vec<u32>, u32> = HashMap::new();
        let mut faces: Vec<Vec<u32>> = Vec::new();
        let mut cell_faces = Vec::with_capacity(cells.len());
        for cell in cells {
            let mut list = Vec::with_capacity(cell.len());
            for l in cell {
                let mut key = l.clone();
                key.sort_unstable();
                let id = *ids.entry(key).or_insert_with(|| {
                    faces.push(l.clone());
                    (faces.len() - 1) as u32
                });
                list.push(id);
            }
            cell_faces.push(list);
        }
        LatticeTopology::new(num_vertices, &faces, &cell_faces)
    }

    fn check_connected(&self) -> Result<()> {
        let nc = self.cells.len();
        let mut seen = vec![false; nc];
        let mut stack = vec![0usize];
        seen[0] = true;
        while let Some(c) = stack.pop() {
            for &f in self.cells.row(c) {
                for &d in &self.face_cells[f as usize] {
                    if d != NO_CELL && !seen[d as usize] {
                        seen[d as usize] = true;
                        stack.push(d as usize);
                    }
                }
            }
        }
        match seen.iter().position(|s| !s) {
            Some(c) => Err(Error::Topology(format!(
                "cell {c}: not connected to cell 0 through shared faces (the lattice must be connected)"
            ))),
            None => Ok(()),
        }
    }

    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.cells.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.edges.len()
    }

    /// True for a face with a single cell.
    pub fn is_boundary_face(&self, f: usize) -> bool {
        self.face_cells[f][1] == NO_CELL
    }

    /// Indices of the boundary faces (one cell).
    pub fn boundary_faces(&self) -> Vec<u32> {
        (0..self.num_faces())
            .filter(|&f| self.is_boundary_face(f))
            .map(|f| f as u32)
            .collect()
    }

    /// The faces of cell `c` around its vertex `v` in cyclic order, as the
    /// ring `[e_1, f_1, e_2, f_2, …, e_n, f_n]` where face `f_i` holds edges
    /// `e_i` and `e_{i+1}` (indices into edges and faces). `n` is the valence
    /// of `v` in `c` (MacCracken & Joy 1996, §2.2); `n = 2` happens at an
    /// edge point that local refinement inserted into a neighbour's edge.
    pub fn corner_ring(&self, c: usize, v: u32) -> Result<Vec<u32>> {
        let cell_faces = self.cells.row(c);
        // (face, edge-in, edge-out) for the faces of c at v.
        let mut at_v: Vec<(u32, u32, u32)> = Vec::new();
        for &f in cell_faces {
            let l = self.faces.row(f as usize);
            if let Some(i) = l.iter().position(|&x| x == v) {
                let es = self.face_edges.row(f as usize);
                let prev = es[(i + l.len() - 1) % l.len()];
                at_v.push((f, prev, es[i]));
            }
        }
        let n = at_v.len();
        let bad = || {
            Error::Topology(format!(
                "cell {c}: its faces at vertex {v} do not form one fan (the cell is pinched there)"
            ))
        };
        if n < 2 {
            return Err(bad());
        }
        let mut ring = Vec::with_capacity(2 * n);
        let (f0, e_first, mut e) = at_v[0];
        ring.push(e_first);
        ring.push(f0);
        let mut cur = f0;
        for _ in 1..n {
            let next = at_v
                .iter()
                .find(|&&(f, a, b)| f != cur && (a == e || b == e))
                .ok_or_else(bad)?;
            if ring.iter().skip(1).step_by(2).any(|&f| f == next.0) {
                return Err(bad());
            }
            ring.push(e);
            ring.push(next.0);
            cur = next.0;
            e = if next.1 == e { next.2 } else { next.1 };
        }
        if e != e_first {
            return Err(bad());
        }
        Ok(ring)
    }

    /// Bytes held by the topology's arrays.
    pub fn bytes(&self) -> usize {
        self.faces.bytes()
            + self.cells.bytes()
            + 8 * self.edges.len()
            + self.face_edges.bytes()
            + 8 * self.face_cells.len()
            + self.edge_faces.bytes()
            + self.edge_cells.bytes()
            + self.cell_vertices.bytes()
            + self.vertex_cells.bytes()
            + self.vertex_faces.bytes()
            + self.vertex_edges.bytes()
    }
}

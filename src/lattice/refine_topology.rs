//! One level of Catmull-Clark volume refinement of a lattice's topology
//! (MacCracken & Joy 1996, §2.1–2.2, "reconnection"): the child topology and
//! the description of every child cell as a type-n cell.
//!
//! New vertices are numbered `[old vertices | edge points | face points |
//! cell points]`. A face with `k` vertices becomes `k` quads
//! `(v_i, E(v_i v_{i+1}), F, E(v_{i-1} v_i))`; inside every cell each edge
//! `e` (with the cell's two faces `f_a`, `f_b` at it) gives the quad
//! `(E(e), F(f_a), C, F(f_b))`. Every vertex `v` of a cell gives one child
//! cell with `2n` quad faces, `n` the valence of `v` in the cell.

use crate::error::Result;

use super::topology::{Csr, LatticeTopology};

/// Every cell of a refined lattice is a type-n cell (MacCracken & Joy 1996,
/// §2.2, fig. 2): an apex vertex (an old vertex), a centre (the parent's cell
/// point) and a ring of `2n` vertices alternating edge point and face point,
/// `[E_1, F_1, …, E_n, F_n]`, where `F_i` lies between `E_i` and `E_{i+1}`.
/// Its faces are `(apex, E_i, F_i, E_{i+1})` and `(centre, F_{i-1}, E_i, F_i)`.
/// For `n = 3` it is a hexahedron with trilinear corners
/// `apex = (0,0,0)`, `E_1 = (1,0,0)`, `E_2 = (0,1,0)`, `E_3 = (0,0,1)`,
/// `F_1 = (1,1,0)`, `F_2 = (0,1,1)`, `F_3 = (1,0,1)`, `centre = (1,1,1)`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TypeNCells {
    /// Apex vertex of every cell.
    pub apex: Vec<u32>,
    /// Centre vertex of every cell.
    pub centre: Vec<u32>,
    /// Ring of every cell (`2n` vertices).
    pub ring: Csr,
}

impl TypeNCells {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.apex.len()
    }

    /// True when there is no cell.
    pub fn is_empty(&self) -> bool {
        self.apex.is_empty()
    }

    /// `n` of cell `c` (3 for a hexahedron).
    pub fn valence(&self, c: usize) -> usize {
        self.ring.row(c).len() / 2
    }

    /// The eight vertices of hexahedral cell `c` in trilinear order
    /// `(u,v,w) = 000, 100, 010, 110, 001, 101, 011, 111`; `None` unless `n = 3`.
    pub fn hexahedron(&self, c: usize) -> Option<[u32; 8]> {
        let r = self.ring.row(c);
        if r.len() != 6 {
            return None;
        }
        // E1=100, F1=110, E2=010, F2=011, E3=001, F3=101.
        Some([
            self.apex[c],
            r[0],
            r[2],
            r[1],
            r[4],
            r[5],
            r[3],
            self.centre[c],
        ])
    }

    /// Bytes held by the arrays.
    pub fn bytes(&self) -> usize {
        4 * (self.apex.len() + self.centre.len()) + self.ring.bytes()
    }
}

/// The refined topology and its type-n cells; child cells are numbered by
/// parent cell, then by the parent's vertices in `cell_vertices` order.
pub fn refined_topology(topo: &LatticeTopology) -> Result<(LatticeTopology, TypeNCells)> {
    let parts = refined_parts(topo)?;
    let child = LatticeTopology::new(parts.num_vertices, &parts.faces, &parts.cells)?;
    Ok((child, parts.type_n))
}

/// The refined level's cells as type-n cells and its boundary faces (the
/// children of the parent's boundary faces), without building the full
/// incidence structure of [`refined_topology`]: the type-n cells describe
/// every cell completely (their faces follow from apex, centre and ring),
/// which is all an embedding needs, in a fraction of the memory.
pub fn refined_cells(topo: &LatticeTopology) -> Result<(TypeNCells, Vec<[u32; 4]>)> {
    let parts = refined_parts(topo)?;
    let mut boundary = Vec::new();
    for f in topo.boundary_faces() {
        let (a, b) = (
            topo.faces.offsets[f as usize] as usize,
            topo.faces.offsets[f as usize + 1] as usize,
        );
        boundary.extend_from_slice(&parts.faces[a..b]);
    }
    Ok((parts.type_n, boundary))
}

struct RefinedParts {
    num_vertices: usize,
    faces: Vec<[u32; 4]>,
    cells: Vec<Vec<u32>>,
    type_n: TypeNCells,
}

fn refined_parts(topo: &LatticeTopology) -> Result<RefinedParts> {
    let nv = topo.num_vertices as u32;
    let ne = topo.num_edges() as u32;
    let nf = topo.num_faces() as u32;
    let e_pt = |e: u32| nv + e;
    let f_pt = |f: u32| nv + ne + f;
    let c_pt = |c: u32| nv + ne + nf + c;
    let mut faces: Vec<[u32; 4]> = Vec::with_capacity(topo.faces.items.len() * 3);
    // Children of old faces: child i of face f is at offsets[f] + i.
    for f in 0..topo.num_faces() {
        let l = topo.faces.row(f);
        let es = topo.face_edges.row(f);
        let k = l.len();
        for i in 0..k {
            faces.push([l[i], e_pt(es[i]), f_pt(f as u32), e_pt(es[(i + k - 1) % k])]);
        }
    }
    let mut cells: Vec<Vec<u32>> = Vec::new();
    let mut apex = Vec::new();
    let mut centre = Vec::new();
    let mut rings: Vec<Vec<u32>> = Vec::new();
    for c in 0..topo.num_cells() {
        // Interior faces of this cell, one per cell edge.
        let mut edge_face: Vec<(u32, u32)> = Vec::new();
        for &f in topo.cells.row(c) {
            for &e in topo.face_edges.row(f as usize) {
                if edge_face.iter().all(|&(x, _)| x != e) {
                    edge_face.push((e, 0));
                }
            }
        }
        for &v in topo.cell_vertices.row(c) {
            let ring = topo.corner_ring(c, v)?;
            let n = ring.len() / 2;
            let mut child = Vec::with_capacity(2 * n);
            let mut vring = Vec::with_capacity(2 * n);
            for i in 0..n {
                let (e, f) = (ring[2 * i], ring[2 * i + 1]);
                vring.push(e_pt(e));
                vring.push(f_pt(f));
                // Child of face f at v.
                let l = topo.faces.row(f as usize);
                let pos = l.iter().position(|&x| x == v).unwrap_or(0);
                child.push(topo.faces.offsets[f as usize] + pos as u32);
                // Interior face of (c, e): created once per cell edge.
                let slot = edge_face.iter().position(|&(x, _)| x == e).unwrap_or(0);
                if edge_face[slot].1 == 0 {
                    let f_prev = ring[(2 * i + 2 * n - 1) % (2 * n)];
                    faces.push([e_pt(e), f_pt(f_prev), c_pt(c as u32), f_pt(f)]);
                    edge_face[slot].1 = faces.len() as u32; // 1-based
                }
                child.push(edge_face[slot].1 - 1);
            }
            cells.push(child);
            apex.push(v);
            centre.push(c_pt(c as u32));
            rings.push(vring);
        }
    }
    Ok(RefinedParts {
        num_vertices: (nv + ne + nf) as usize + topo.num_cells(),
        faces,
        cells,
        type_n: TypeNCells {
            apex,
            centre,
            ring: Csr::from_lists(&rings),
        },
    })
}

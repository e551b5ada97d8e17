//! Local octree refinement of chosen cells (multiresolution-lattice FFD
//! paper, §2.2 and fig. 3: "apply octree subdivision rules only to
//! user-specified cells … although it complicates the local topological
//! structure, the resulting lattice is still valid").
//!
//! Every chosen cell gets the octree points of §2.1 — a cell point (average
//! of its vertices), a face point per face (average of the face's
//! vertices), an edge point per edge (midpoint) — and is replaced by one
//! child per vertex, connected as in Catmull-Clark reconnection (the same
//! children as [`refined_topology`](super::refined_topology)). Cells that
//! are not chosen keep their shape but not their topology: a face shared with
//! a chosen cell is replaced by its sub-quads, and every face through a split
//! edge gets the edge point in its loop. They become the non-hexahedral cells
//! the paper describes: a face neighbour has 9 faces and a face point of
//! valence 4; an edge neighbour has two pentagons meeting at an edge point of
//! valence 2. Under Catmull-Clark refinement a cell vertex of valence `n`
//! gives a type-`n` cell, so type-2 and type-4 cells appear exactly there.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::lattice::Lattice;
use super::topology::LatticeTopology;

/// What [`locally_refined`] made.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LocalRefineReport {
    /// Cells refined.
    pub refined: usize,
    /// Cells of the new lattice.
    pub cells: usize,
    /// Cells of the new lattice that are not hexahedra (not six quads).
    pub non_hexahedral: usize,
    /// `(cell, vertex)` pairs of the new lattice whose valence in the cell is not 3:
    /// where refinement makes type-n cells with `n ≠ 3`.
    pub extraordinary_corners: usize,
}

fn average(positions: &[Point3], vs: &[u32]) -> Point3 {
    let s = vs
        .iter()
        .fold(Vector3::zeros(), |s, &v| s + positions[v as usize].coords);
    Point3::from(s / vs.len() as Real)
}

/// The lattice with the cells `chosen` refined by the octree rules; the
/// other cells keep their indices, the children of chosen cells follow.
/// New vertices are numbered `[old | edge points | face points | cell points]`.
pub fn locally_refined(
    lattice: &Lattice,
    chosen: &[usize],
) -> Result<(Lattice, LocalRefineReport)> {
    let t = &lattice.topology;
    let nc = t.num_cells();
    let mut refine = vec![false; nc];
    for &c in chosen {
        *refine.get_mut(c).ok_or_else(|| {
            Error::out_of_range(format!(
                "cell {c} does not exist (the lattice has {nc} cells)"
            ))
        })? = true;
    }
    let cells_r: Vec<usize> = (0..nc).filter(|&c| refine[c]).collect();
    if cells_r.is_empty() {
        return Err(Error::input("no cell chosen for local refinement"));
    }
    let mut positions = lattice.positions.clone();
    // Edge, face and cell points of the chosen cells.
    let mut edge_pt: HashMap<u32, u32> = HashMap::new();
    let mut face_pt: HashMap<u32, u32> = HashMap::new();
    let new_point = |positions: &mut Vec<Point3>, vs: &[u32]| {
        positions.push(average(positions, vs));
        (positions.len() - 1) as u32
    };
    let mut split_edges: Vec<u32> = Vec::new();
    let mut split_faces: Vec<u32> = Vec::new();
    for &c in &cells_r {
        for &f in t.cells.row(c) {
            for &e in t.face_edges.row(f as usize) {
                if let std::collections::hash_map::Entry::Vacant(slot) = edge_pt.entry(e) {
                    slot.insert(0);
                    split_edges.push(e);
                }
            }
            if let std::collections::hash_map::Entry::Vacant(slot) = face_pt.entry(f) {
                slot.insert(0);
                split_faces.push(f);
            }
        }
    }
    for &e in &split_edges {
        let id = new_point(&mut positions, &t.edges[e as usize]);
        edge_pt.insert(e, id);
    }
    for &f in &split_faces {
        let id = new_point(&mut positions, t.faces.row(f as usize));
        face_pt.insert(f, id);
    }
    let cell_pt: Vec<u32> = cells_r
        .iter()
        .map(|&c| new_point(&mut positions, t.cell_vertices.row(c)))
        .collect();
    let ep = |e: u32| edge_pt.get(&e).copied();
    // Faces: unsplit faces (with edge points inserted) keep their index;
    // split faces become sub-quads appended after them.
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(t.num_faces());
    let mut sub_quads: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut kept_face = vec![u32::MAX; t.num_faces()];
    for (f, kept) in kept_face.iter_mut().enumerate() {
        if face_pt.contains_key(&(f as u32)) {
            continue;
        }
        *kept = faces.len() as u32;
        let l = t.faces.row(f);
        let es = t.face_edges.row(f);
        let mut loop_ = Vec::with_capacity(l.len() + 4);
        for i in 0..l.len() {
            loop_.push(l[i]);
            if let Some(m) = ep(es[i]) {
                loop_.push(m);
            }
        }
        faces.push(loop_);
    }
    for &f in &split_faces {
        let l = t.faces.row(f as usize);
        let es = t.face_edges.row(f as usize);
        let k = l.len();
        let fp = face_pt[&f];
        let mut ids = Vec::with_capacity(k);
        for i in 0..k {
            let (a, b) = (ep(es[i]), ep(es[(i + k - 1) % k]));
            let (Some(a), Some(b)) = (a, b) else {
                return Err(Error::Topology(format!("face {f}: an edge was not split")));
            };
            faces.push(vec![l[i], a, fp, b]);
            ids.push((faces.len() - 1) as u32);
        }
        sub_quads.insert(f, ids);
    }
    // Cells: unchosen cells with split faces replaced by their sub-quads.
    let mut cells: Vec<Vec<u32>> = Vec::with_capacity(nc + 7 * cells_r.len());
    for c in (0..nc).filter(|&c| !refine[c]) {
        let mut list = Vec::new();
        for &f in t.cells.row(c) {
            match sub_quads.get(&f) {
                Some(q) => list.extend_from_slice(q),
                None => list.push(kept_face[f as usize]),
            }
        }
        cells.push(list);
    }
    for (ci, &c) in cells_r.iter().enumerate() {
        let cp = cell_pt[ci];
        // One interior quad per cell edge: (E(e), F(f_a), C, F(f_b)).
        let mut inner: HashMap<u32, u32> = HashMap::new();
        for &v in t.cell_vertices.row(c) {
            let ring = t.corner_ring(c, v)?;
            let n = ring.len() / 2;
            let mut child = Vec::with_capacity(2 * n);
            for i in 0..n {
                let (e, f) = (ring[2 * i], ring[2 * i + 1]);
                let pos = t.faces.row(f as usize).iter().position(|&x| x == v);
                let q = pos.and_then(|p| sub_quads.get(&f).map(|s| s[p]));
                child.push(q.ok_or_else(|| {
                    Error::Topology(format!("cell {c}: face {f} was not split at vertex {v}"))
                })?);
                let id = match inner.get(&e) {
                    Some(&id) => id,
                    None => {
                        let f_prev = ring[(2 * i + 2 * n - 1) % (2 * n)];
                        let m = ep(e).unwrap_or(u32::MAX);
                        faces.push(vec![m, face_pt[&f_prev], cp, face_pt[&f]]);
                        let id = (faces.len() - 1) as u32;
                        inner.insert(e, id);
                        id
                    }
                };
                child.push(id);
            }
            cells.push(child);
        }
    }
    let topo = LatticeTopology::new(positions.len(), &faces, &cells)?;
    let report = LocalRefineReport {
        refined: cells_r.len(),
        cells: topo.num_cells(),
        non_hexahedral: (0..topo.num_cells())
            .filter(|&c| {
                let fs = topo.cells.row(c);
                fs.len() != 6 || fs.iter().any(|&f| topo.faces.row(f as usize).len() != 4)
            })
            .count(),
        extraordinary_corners: (0..topo.num_cells())
            .map(|c| {
                topo.cell_vertices
                    .row(c)
                    .iter()
                    .filter(|&&v| topo.corner_ring(c, v).ok().is_none_or(|r| r.len() != 6))
                    .count()
            })
            .sum(),
    };
    Ok((Lattice::new(positions, topo)?, report))
}

//! Local (adaptive) Catmull-Clark refinement: only marked faces are split.
//!
//! A marked `n`-gon becomes the `n` quads `(vᵢ, E(eᵢ), F(f), E(eᵢ₋₁))` of
//! uniform refinement (see [`refine_topology`](super::refine_topology)). An
//! unmarked face keeps its corners and takes the edge point of each of its
//! split edges as an extra corner (a T-vertex), so it becomes an
//! `(n + k)`-gon; Catmull-Clark's rules for general polygons (Catmull and
//! Clark 1978) keep the limit surface across such a transition smooth away
//! from the new extraordinary points. [`close_marks`] first marks every face
//! that would gain as many corners as it has, so quads gain at most one.
//!
//! Positions come from the uniform stencil's rows wherever their whole
//! support is refined: every face point (the centroid), edge points of edges
//! whose faces are all marked (the smooth rule, or the boundary midpoint),
//! vertex points of vertices whose faces are all marked (smooth or boundary
//! rule). At the transition the parent stays in place: a split edge with an
//! unmarked face gets its midpoint, a vertex with an unmarked face keeps its
//! position. So the limit surface is unchanged deep inside the refined
//! region and far outside it, and moves near the transition; this is a
//! starting point for a fit that goes on, not an exact refinement.

use crate::error::{Error, Result};
use crate::math::Point3;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;
use crate::topology::{Level, NONE};

/// The locally refined mesh and how its vertices follow the parent's.
#[derive(Clone, Debug)]
pub struct LocalRefinement {
    /// The refined control mesh (positions `stencil · parent positions`).
    /// Vertex `v < parent vertices` is parent vertex `v`; then come the face
    /// points of the marked faces and the edge points of the split edges.
    pub mesh: PolyMesh,
    /// `P_child = S P_parent`.
    pub stencil: StencilTable,
    /// Parent face of every child face.
    pub parent_face: Vec<u32>,
    /// The vertex of one uniform refinement step that every child vertex
    /// stands for (its row in the uniform stencil).
    pub uniform_vertex: Vec<u32>,
    /// Where each parent corner's level-1 sub-face (corner `i` of face `f`,
    /// index `face_offsets[f] + i`) lies in the child mesh.
    pub corner_image: Vec<CornerImage>,
}

/// The child-mesh image of a parent's level-1 sub-face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CornerImage {
    /// The whole child face (a split face's quad at that corner), with the
    /// same corner frame.
    Face(u32),
    /// The same level-1 sub-face of a child face that kept the parent's
    /// corners: child face, corner.
    Corner(u32, u32),
    /// The sub-face of a face that gained corners: its shape changed, and
    /// the child face's sub-face at the same corner vertex (child face,
    /// corner) is another surface piece nearby (a start for searches only).
    Changed(u32, u32),
}

/// The marks extended until no unmarked face has at least half of its edges
/// split (shared with a marked face): a quad then gains at most one corner.
pub fn close_marks(level: &Level, marked: &[bool]) -> Vec<bool> {
    let mut marked = marked.to_vec();
    loop {
        let mut changed = false;
        for f in 0..level.num_faces() {
            if marked[f] {
                continue;
            }
            let edges = level.face_edge_list(f);
            let split = edges
                .iter()
                .filter(|&&e| {
                    level.edge_faces[e as usize]
                        .iter()
                        .any(|&g| g != NONE && g as usize != f && marked[g as usize])
                })
                .count();
            if 2 * split > edges.len() {
                marked[f] = true;
                changed = true;
            }
        }
        if !changed {
            return marked;
        }
    }
}

/// Splits the `marked` faces of `parent` (topology `level`, one uniform
/// Catmull-Clark step `uniform` from it: rows face points, edge points,
/// vertex points as [`refine_stencil`](super::refine_stencil) orders them).
pub fn refine_marked(
    parent: &PolyMesh,
    level: &Level,
    uniform: &StencilTable,
    marked: &[bool],
) -> Result<LocalRefinement> {
    let (nf, ne, nv) = (level.num_faces(), level.num_edges(), level.num_vertices);
    if marked.len() != nf || uniform.num_rows() != nf + ne + nv {
        return Err(Error::size_mismatch(format!(
            "local refinement: {} marks and {} stencil rows for {nf} faces, {ne} edges, {nv} vertices",
            marked.len(),
            uniform.num_rows()
        )));
    }
    let is_marked = |f: u32| f != NONE && marked[f as usize];
    let split = |e: usize| level.edge_faces[e].iter().any(|&f| is_marked(f));
    // New vertex numbers: parent vertices, face points, edge points.
    let mut face_point = vec![NONE; nf];
    let mut edge_point = vec![NONE; ne];
    let mut next = nv as u32;
    for (f, fp) in face_point.iter_mut().enumerate() {
        if marked[f] {
            *fp = next;
            next += 1;
        }
    }
    for (e, ep) in edge_point.iter_mut().enumerate() {
        if split(e) {
            *ep = next;
            next += 1;
        }
    }
    let mut stencil = StencilTable::with_capacity(nv, next as usize, 0);
    let mut uniform_vertex = Vec::with_capacity(next as usize);
    let copy = |s: &mut StencilTable, r: usize| {
        let (c, w) = uniform.row(r);
        s.push_row(c.iter().copied().zip(w.iter().copied()));
    };
    for v in 0..nv {
        let faces = level.vertex_faces(v);
        uniform_vertex.push((nf + ne + v) as u32);
        if !faces.is_empty() && faces.iter().all(|&f| is_marked(f)) {
            copy(&mut stencil, nf + ne + v);
        } else {
            stencil.push_row([(v as u32, 1.0)]);
        }
    }
    for f in (0..nf).filter(|&f| marked[f]) {
        uniform_vertex.push(f as u32);
        copy(&mut stencil, f);
    }
    for e in (0..ne).filter(|&e| split(e)) {
        uniform_vertex.push((nf + e) as u32);
        let [a, b] = level.edge_faces[e];
        if is_marked(a) && (b == NONE || is_marked(b)) {
            copy(&mut stencil, nf + e);
        } else {
            let [v0, v1] = level.edge_verts[e];
            stencil.push_row([(v0, 0.5), (v1, 0.5)]);
        }
    }
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(nf + 3 * marked.len());
    let mut parent_face = Vec::with_capacity(faces.capacity());
    let mut corner_image = Vec::with_capacity(level.face_verts.len());
    for f in 0..nf {
        let fv = level.face_vertices(f);
        let fe = level.face_edge_list(f);
        let n = fv.len();
        if marked[f] {
            for i in 0..n {
                let (e_i, e_p) = (fe[i] as usize, fe[(i + n - 1) % n] as usize);
                corner_image.push(CornerImage::Face(faces.len() as u32));
                faces.push(vec![fv[i], edge_point[e_i], face_point[f], edge_point[e_p]]);
                parent_face.push(f as u32);
            }
        } else {
            let mut face = Vec::with_capacity(n + 2);
            for i in 0..n {
                face.push(fv[i]);
                if edge_point[fe[i] as usize] != NONE {
                    face.push(edge_point[fe[i] as usize]);
                }
            }
            let g = faces.len() as u32;
            corner_image.extend((0..n).map(|i| {
                if face.len() == n {
                    CornerImage::Corner(g, i as u32)
                } else {
                    let j = face.iter().position(|&v| v == fv[i]).unwrap_or(i);
                    CornerImage::Changed(g, j as u32)
                }
            }));
            faces.push(face);
            parent_face.push(f as u32);
        }
    }
    let positions: Vec<Point3> = stencil.apply(&parent.positions)?;
    Ok(LocalRefinement {
        mesh: PolyMesh::from_faces(positions, &faces)?,
        stencil,
        parent_face,
        uniform_vertex,
        corner_image,
    })
}

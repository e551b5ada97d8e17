//! Connectivity of the next level for face-splitting schemes (Catmull-Clark):
//! every `n`-gon becomes `n` quads.
//!
//! Child vertices are numbered face points first, then edge points, then
//! vertex points (OpenSubdiv's default order): face point of face `f` is `f`,
//! edge point of edge `e` is `F + e`, vertex point of vertex `v` is `F + E + v`.
//! The child quad at corner `i` of face `f` is `(V(vᵢ), E(eᵢ), F(f), E(eᵢ₋₁))`
//! and has index `face_offsets[f] + i`.

use rayon::prelude::*;

use crate::topology::{Level, NONE, face_of_corner};

/// Below this many face corners the work is done on the calling thread.
const PARALLEL_MIN: usize = 16384;

/// The refined connectivity of `parent`.
pub fn refine_topology(parent: &Level) -> Level {
    let nf = parent.num_faces();
    let ne = parent.num_edges();
    let nv = parent.num_vertices;
    let nc = parent.face_verts.len(); // corners = child faces = interior child edges
    let face_of = face_of_corner(&parent.face_offsets);
    let (fpt, ept, vpt) = (0u32, nf as u32, (nf + ne) as u32);

    // Child faces: 4 vertices and 4 edges each.
    let mut face_verts = vec![0u32; 4 * nc];
    let mut face_edges = vec![0u32; 4 * nc];
    let par = nc >= PARALLEL_MIN;
    let child_face = |(c, (fv, fe)): (usize, (&mut [u32], &mut [u32]))| {
        let f = face_of[c] as usize;
        let a = parent.face_offsets[f] as usize;
        let n = parent.face_offsets[f + 1] as usize - a;
        let i = c - a;
        let prev = a + (i + n - 1) % n;
        let v = parent.face_verts[c];
        let e_i = parent.face_edges[c];
        let e_p = parent.face_edges[prev];
        fv.copy_from_slice(&[vpt + v, ept + e_i, fpt + f as u32, ept + e_p]);
        let half = |e: u32| -> u32 {
            if parent.edge_verts[e as usize][0] == v {
                2 * e
            } else {
                2 * e + 1
            }
        };
        fe.copy_from_slice(&[
            half(e_i),
            (2 * ne + c) as u32,
            (2 * ne + prev) as u32,
            half(e_p),
        ]);
    };
    if par {
        face_verts
            .par_chunks_mut(4)
            .zip(face_edges.par_chunks_mut(4))
            .enumerate()
            .for_each(child_face);
    } else {
        face_verts
            .chunks_mut(4)
            .zip(face_edges.chunks_mut(4))
            .enumerate()
            .for_each(child_face);
    }

    // Child edges: two halves per parent edge, then one per parent corner.
    let mut edge_verts = vec![[0u32; 2]; 2 * ne + nc];
    let mut edge_faces = vec![[NONE; 2]; 2 * ne + nc];
    let (halves_v, inner_v) = edge_verts.split_at_mut(2 * ne);
    let half_verts = |(e, hv): (usize, &mut [[u32; 2]])| {
        let [a, b] = parent.edge_verts[e];
        let m = ept + e as u32;
        hv[0] = [vpt + a, m];
        hv[1] = [m, vpt + b];
    };
    let inner_verts = |(c, ev): (usize, &mut [u32; 2])| {
        *ev = [ept + parent.face_edges[c], fpt + face_of[c]];
    };
    // Faces of the halves: the edge's direction is that of its first face, so
    // in face k of the edge the half at `edge_verts[0]` belongs to the child
    // quad at that vertex's corner.
    let (halves_f, inner_f) = edge_faces.split_at_mut(2 * ne);
    let half_faces = |(e, hf): (usize, &mut [[u32; 2]])| {
        let [a, b] = parent.edge_verts[e];
        for (k, &f) in parent.edge_faces[e].iter().enumerate() {
            if f == NONE {
                continue;
            }
            let f = f as usize;
            let off = parent.face_offsets[f] as usize;
            let ca = off + parent.corner_in_face(f, a).unwrap_or(0);
            let cb = off + parent.corner_in_face(f, b).unwrap_or(0);
            // In face 0 the edge runs a -> b, in face 1 b -> a; either way
            // the half at a lies in the child quad of a's corner.
            hf[0][k] = ca as u32;
            hf[1][k] = cb as u32;
        }
    };
    let inner_faces = |(c, ef): (usize, &mut [u32; 2])| {
        let f = face_of[c] as usize;
        let a = parent.face_offsets[f] as usize;
        let n = parent.face_offsets[f + 1] as usize - a;
        let next = a + (c - a + 1) % n;
        *ef = [c as u32, next as u32];
    };
    if par {
        halves_v.par_chunks_mut(2).enumerate().for_each(half_verts);
        inner_v.par_iter_mut().enumerate().for_each(inner_verts);
        halves_f.par_chunks_mut(2).enumerate().for_each(half_faces);
        inner_f.par_iter_mut().enumerate().for_each(inner_faces);
    } else {
        halves_v.chunks_mut(2).enumerate().for_each(half_verts);
        inner_v.iter_mut().enumerate().for_each(inner_verts);
        halves_f.chunks_mut(2).enumerate().for_each(half_faces);
        inner_f.iter_mut().enumerate().for_each(inner_faces);
    }

    let mut child = Level {
        num_vertices: nf + ne + nv,
        face_offsets: (0..=nc as u32).map(|i| 4 * i).collect(),
        face_verts,
        face_edges,
        edge_verts,
        edge_faces,
        ..Default::default()
    };
    child.build_vertex_adjacency();
    child
}

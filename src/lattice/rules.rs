//! The Catmull-Clark volume refinement rules with boundary control, as one
//! stencil table per level (MacCracken & Joy 1996, §2.2 and §3).
//!
//! Rows are numbered like the child vertices: `[vertex points | edge points |
//! face points | cell points]`; columns are the parent's vertices. With `C`
//! cell points (average of a cell's vertices), `A` face centroids and `M`
//! edge midpoints:
//!
//! - cell point: the average of the cell's vertices;
//! - interior face point: `F = (C₀ + 2A + C₁) / 4`;
//! - interior edge point: `E = (C_avg + 2 A_avg + (n − 3) M) / n`, `n` the
//!   number of faces containing the edge;
//! - interior vertex point: `V = (C_avg + 3 A_avg + 3 M_avg + P) / 8`;
//! - boundary face (one cell): the surface face point, its centroid;
//! - boundary, non-sharp edge with two boundary faces: the surface edge point
//!   `(a + b + A₀ + A₁) / 4` (Catmull & Clark 1978);
//! - sharp edge: the cubic B-spline curve edge point, the midpoint;
//! - boundary vertex on exactly two sharp edges: the B-spline curve vertex
//!   point `(a + 6P + b) / 8`; on three or more: fixed;
//! - other boundary vertex: the surface vertex point `(Q + 2R + (n − 3) P) / n`
//!   over its `n` boundary edges, `Q` the average centroid of its boundary
//!   faces and `R` the average midpoint of its boundary edges;
//! - corner vertex: fixed.
//!
//! Every row sums to one, so the map is affine invariant.

use crate::stencil::{RowBuilder, StencilTable};

use super::lattice::BoundaryTags;
use super::topology::{LatticeTopology, NO_CELL};

/// The level's refinement stencil `P_{k+1} = S_k P_k` (rows: child vertices).
pub fn refinement_stencil(topo: &LatticeTopology, tags: &BoundaryTags) -> StencilTable {
    let nv = topo.num_vertices;
    let ne = topo.num_edges();
    let nf = topo.num_faces();
    let nc = topo.num_cells();
    let is_bface = |f: u32| topo.face_cells[f as usize][1] == NO_CELL;
    let cell_row = |c: u32, s: f64, b: &mut RowBuilder| {
        let vs = topo.cell_vertices.row(c as usize);
        for &v in vs {
            b.add(v, s / vs.len() as f64);
        }
    };
    let centroid_row = |f: u32, s: f64, b: &mut RowBuilder| {
        let vs = topo.faces.row(f as usize);
        for &v in vs {
            b.add(v, s / vs.len() as f64);
        }
    };
    let mid_row = |e: u32, s: f64, b: &mut RowBuilder| {
        let [x, y] = topo.edges[e as usize];
        b.add(x, 0.5 * s);
        b.add(y, 0.5 * s);
    };
    let boundary_faces_of_edge = |e: usize| -> Vec<u32> {
        topo.edge_faces
            .row(e)
            .iter()
            .copied()
            .filter(|&f| is_bface(f))
            .collect()
    };
    StencilTable::from_row_fn(nv + ne + nf + nc, nv, |r, b| {
        if r < nv {
            let v = r as u32;
            let bfaces: Vec<u32> = topo
                .vertex_faces
                .row(r)
                .iter()
                .copied()
                .filter(|&f| is_bface(f))
                .collect();
            if tags.corners[r] {
                b.add(v, 1.0);
            } else if !bfaces.is_empty() {
                let sharp: Vec<u32> = topo
                    .vertex_edges
                    .row(r)
                    .iter()
                    .copied()
                    .filter(|&e| tags.sharp_edges[e as usize])
                    .collect();
                if sharp.len() == 2 {
                    b.add(v, 0.75);
                    for e in sharp {
                        let [x, y] = topo.edges[e as usize];
                        b.add(if x == v { y } else { x }, 0.125);
                    }
                } else if sharp.len() > 2 {
                    b.add(v, 1.0);
                } else {
                    let bedges: Vec<u32> = topo
                        .vertex_edges
                        .row(r)
                        .iter()
                        .copied()
                        .filter(|&e| topo.edge_faces.row(e as usize).iter().any(|&f| is_bface(f)))
                        .collect();
                    let n = bedges.len() as f64;
                    for &f in &bfaces {
                        centroid_row(f, 1.0 / (n * bfaces.len() as f64), b);
                    }
                    for &e in &bedges {
                        mid_row(e, 2.0 / (n * n), b);
                    }
                    b.add(v, (n - 3.0) / n);
                }
            } else {
                let cs = topo.vertex_cells.row(r);
                for &c in cs {
                    cell_row(c, 1.0 / (8.0 * cs.len() as f64), b);
                }
                let fs = topo.vertex_faces.row(r);
                for &f in fs {
                    centroid_row(f, 3.0 / (8.0 * fs.len() as f64), b);
                }
                let es = topo.vertex_edges.row(r);
                for &e in es {
                    mid_row(e, 3.0 / (8.0 * es.len() as f64), b);
                }
                b.add(v, 0.125);
            }
        } else if r < nv + ne {
            let e = r - nv;
            let bfaces = boundary_faces_of_edge(e);
            if tags.sharp_edges[e] || (!bfaces.is_empty() && bfaces.len() != 2) {
                mid_row(e as u32, 1.0, b);
            } else if bfaces.len() == 2 {
                mid_row(e as u32, 0.5, b);
                centroid_row(bfaces[0], 0.25, b);
                centroid_row(bfaces[1], 0.25, b);
            } else {
                let fs = topo.edge_faces.row(e);
                let cs = topo.edge_cells.row(e);
                let n = fs.len() as f64;
                for &c in cs {
                    cell_row(c, 1.0 / (n * cs.len() as f64), b);
                }
                for &f in fs {
                    centroid_row(f, 2.0 / (n * n), b);
                }
                mid_row(e as u32, (n - 3.0) / n, b);
            }
        } else if r < nv + ne + nf {
            let f = (r - nv - ne) as u32;
            let [c0, c1] = topo.face_cells[f as usize];
            if c1 == NO_CELL {
                centroid_row(f, 1.0, b);
            } else {
                cell_row(c0, 0.25, b);
                cell_row(c1, 0.25, b);
                centroid_row(f, 0.5, b);
            }
        } else {
            cell_row((r - nv - ne - nf) as u32, 1.0, b);
        }
    })
}

/// Tags of the child level: children of sharp edges are sharp, corners stay
/// corners; nothing else is tagged (MacCracken & Joy 1996, §3: the tags
/// describe the same curves and points at every level).
pub fn refined_tags(
    parent: &LatticeTopology,
    tags: &BoundaryTags,
    child: &LatticeTopology,
) -> BoundaryTags {
    let nv = parent.num_vertices;
    let mut corners = vec![false; child.num_vertices];
    corners[..nv].copy_from_slice(&tags.corners);
    let mut sharp_edges = vec![false; child.num_edges()];
    for (e, &[a, b]) in parent.edges.iter().enumerate() {
        if !tags.sharp_edges[e] {
            continue;
        }
        for &ce in child.vertex_edges.row(nv + e) {
            let [x, y] = child.edges[ce as usize];
            if x == a || x == b || y == a || y == b {
                sharp_edges[ce as usize] = true;
            }
        }
    }
    BoundaryTags {
        corners,
        sharp_edges,
    }
}

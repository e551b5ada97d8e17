//! Edge loops of a mesh whose vertices have valence 4 (a converted Doo-Sabin
//! mesh): "a loop is identified by tracing the opposite edge each time we
//! enter a new vertex" (fine-tuning paper, §4.4). Every edge lies in exactly
//! one loop. A loop stops (and is open) at a vertex that is not an interior
//! valence-4 vertex.

use crate::topology::Level;

/// One edge loop: `edges[k]` joins `vertices[k]` and `vertices[k + 1]`
/// (indices mod `vertices.len()` when `closed`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EdgeLoop {
    /// Vertices in order (`edges.len()` of them when closed, one more when open).
    pub vertices: Vec<u32>,
    /// Edges in order.
    pub edges: Vec<u32>,
    /// True when the loop closes on itself.
    pub closed: bool,
}

/// For every vertex, its edges in cyclic order when it is an interior
/// valence-4 vertex, else `None`.
fn straight_rings(level: &Level) -> Vec<Option<[u32; 4]>> {
    (0..level.num_vertices)
        .map(|v| {
            if level.valence(v) != 4 || level.is_boundary_vertex(v) {
                return None;
            }
            let ring = level.vertex_ring(v);
            (ring.edges.len() == 4)
                .then(|| [ring.edges[0], ring.edges[1], ring.edges[2], ring.edges[3]])
        })
        .collect()
}

/// The edge opposite `e` at `v`, when `v` is an interior valence-4 vertex.
fn opposite(rings: &[Option<[u32; 4]>], v: u32, e: u32) -> Option<u32> {
    let r = rings[v as usize]?;
    let k = r.iter().position(|&x| x == e)?;
    Some(r[(k + 2) % 4])
}

/// All edge loops of `level`; every edge appears in exactly one.
///
/// ```
/// let torus = subdyn::examples::torus(4, 3, 2.0, 0.5);
/// let level = subdyn::topology::Level::from_mesh(&torus).unwrap();
/// let loops = subdyn::finetune::edge_loops(&level);
/// assert_eq!(loops.len(), 4 + 3); // the meridians and the parallels
/// assert!(loops.iter().all(|l| l.closed));
/// ```
pub fn edge_loops(level: &Level) -> Vec<EdgeLoop> {
    let rings = straight_rings(level);
    let mut used = vec![false; level.num_edges()];
    let mut loops = Vec::new();
    for start in 0..level.num_edges() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let [a, b] = level.edge_verts[start];
        // Walks on from vertex `v` away over edge `e`, marking edges used,
        // pushing each edge and its far vertex; `true` when it came back to
        // `start` (a closed loop).
        let mut walk = |mut v: u32, mut e: u32, vs: &mut Vec<u32>, es: &mut Vec<u32>| {
            while let Some(next) = opposite(&rings, v, e) {
                if next as usize == start {
                    return true;
                }
                if used[next as usize] {
                    break;
                }
                used[next as usize] = true;
                v = level.other_vertex(next as usize, v);
                e = next;
                es.push(e);
                vs.push(v);
            }
            false
        };
        // Forward from b; an open loop also backward from a, prepended.
        let mut fwd_v = vec![a, b];
        let mut fwd_e = vec![start as u32];
        let closed = walk(b, start as u32, &mut fwd_v, &mut fwd_e);
        if closed {
            fwd_v.pop(); // the last vertex is `a` again
        } else {
            let (mut back_v, mut back_e) = (Vec::new(), Vec::new());
            walk(a, start as u32, &mut back_v, &mut back_e);
            back_v.reverse();
            back_e.reverse();
            back_v.extend(fwd_v);
            back_e.extend(fwd_e);
            fwd_v = back_v;
            fwd_e = back_e;
        }
        loops.push(EdgeLoop {
            vertices: fwd_v,
            edges: fwd_e,
            closed,
        });
    }
    loops
}

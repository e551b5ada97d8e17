//! Collapse of the binary SAH tree into the 4-wide tree the queries walk:
//! each node pulls up grandchildren, largest surface area first, until it has
//! four children (Wald, Benthin, Boulos, "Getting rid of packets", IEEE
//! Symposium on Interactive Ray Tracing 2008). Child boxes are stored as
//! `f32` relative to the root box's centre, rounded outward, so they still
//! contain the exact boxes: half the memory traffic of `f64` boxes, and the
//! queries stay exact.

use crate::math::Real;

use super::bvh_build::Node;

/// A 4-wide node: child boxes (`f32`, relative to the tree's origin, rounded
/// outward) as `[axis][child]`; child `i` is a leaf holding `count[i] > 0`
/// triangle slots from `child[i]`, an inner node `child[i]` when
/// `count[i] == 0`, or empty (`child[i] == EMPTY`, inverted box).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node4 {
    pub lo: [[f32; 4]; 3],
    pub hi: [[f32; 4]; 3],
    pub child: [u32; 4],
    pub count: [u32; 4],
}

/// Marks an unused child slot of a [`Node4`].
pub(crate) const EMPTY: u32 = u32::MAX;

impl Node4 {
    const NONE: Node4 = Node4 {
        lo: [[f32::INFINITY; 4]; 3],
        hi: [[f32::NEG_INFINITY; 4]; 3],
        child: [EMPTY; 4],
        count: [0; 4],
    };
}

/// Collapses the binary tree `nodes` (root 0) into 4-wide nodes (root 0)
/// with boxes relative to `origin`.
pub(crate) fn collapse(nodes: &[Node], origin: &[Real; 3]) -> Vec<Node4> {
    let mut out = Vec::with_capacity(nodes.len() / 2 + 1);
    emit(nodes, 0, origin, &mut out);
    out
}

/// Appends the 4-wide node for binary node `bin` (and, depth first, its
/// descendants); returns its index.
fn emit(nodes: &[Node], bin: usize, origin: &[Real; 3], out: &mut Vec<Node4>) -> u32 {
    let index = out.len();
    out.push(Node4::NONE);
    let mut kids: Vec<usize> = if nodes[bin].count > 0 {
        vec![bin]
    } else {
        vec![bin + 1, nodes[bin].first as usize]
    };
    while kids.len() < 4 {
        let widest = kids
            .iter()
            .enumerate()
            .filter(|(_, k)| nodes[**k].count == 0)
            .max_by(|a, b| {
                let area = |k: usize| nodes[k].bounds.half_area();
                area(*a.1).total_cmp(&area(*b.1))
            })
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let k = kids.swap_remove(i);
        kids.push(k + 1);
        kids.push(nodes[k].first as usize);
    }
    let mut node = Node4::NONE;
    for (i, &k) in kids.iter().enumerate() {
        let b = &nodes[k].bounds;
        for (axis, &o) in origin.iter().enumerate() {
            node.lo[axis][i] = round_down(b.lo[axis] - o);
            node.hi[axis][i] = round_up(b.hi[axis] - o);
        }
        if nodes[k].count > 0 {
            node.child[i] = nodes[k].first;
            node.count[i] = nodes[k].count;
        } else {
            node.child[i] = emit(nodes, k, origin, out);
        }
    }
    out[index] = node;
    index as u32
}

/// The largest `f32` not above `x`.
fn round_down(x: Real) -> f32 {
    let y = x as f32;
    if Real::from(y) > x { y.next_down() } else { y }
}

/// The smallest `f32` not below `x`.
fn round_up(x: Real) -> f32 {
    let y = x as f32;
    if Real::from(y) < x { y.next_up() } else { y }
}

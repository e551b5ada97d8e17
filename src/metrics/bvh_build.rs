//! Binned SAH construction of the flat node array of a
//! [`TriangleBvh`](super::TriangleBvh).
//!
//! Wald, "On fast construction of SAH-based bounding volume hierarchies",
//! IEEE Symposium on Interactive Ray Tracing 2007: triangle centroids are
//! binned into [`BINS`] slabs along the widest centroid axis, and the split
//! minimising the surface-area heuristic
//! `C = A_L N_L + A_R N_R` (relative to the parent's `A N`) is taken when it
//! is cheaper than a leaf. Below [`MEDIAN_DEPTH`] levels, or when all
//! centroids coincide, the split is the object median (so the depth stays
//! logarithmic on any input and the traversal stack is bounded).
//! The two children of a large range are built in parallel
//! ([`PARALLEL_BUILD`]); the splits and the layout do not depend on the
//! thread count. The binary tree is then made 4-wide by `bvh_collapse`.

use crate::math::Real;

/// Bins per SAH split search.
const BINS: usize = 16;
/// Largest leaf.
pub(crate) const MAX_LEAF: usize = 4;
/// Relative cost of a triangle test against one node visit.
const TRI_COST: Real = 1.0;
/// From this depth on, splits are object medians.
const MEDIAN_DEPTH: usize = 40;
/// Depth bound of the tree: `MEDIAN_DEPTH` plus ⌈log₂ 2³²⌉ median levels.
pub(crate) const MAX_DEPTH: usize = MEDIAN_DEPTH + 33;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Aabb {
    pub lo: [Real; 3],
    pub hi: [Real; 3],
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        lo: [Real::INFINITY; 3],
        hi: [Real::NEG_INFINITY; 3],
    };

    pub fn grow(&mut self, p: &[Real; 3]) {
        for (k, &x) in p.iter().enumerate() {
            self.lo[k] = self.lo[k].min(x);
            self.hi[k] = self.hi[k].max(x);
        }
    }

    /// The box of a triangle's corners.
    pub fn of_triangle(corners: [crate::math::Point3; 3]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in corners {
            b.grow(&[p.x, p.y, p.z]);
        }
        b
    }

    /// The largest side (0 for an empty box).
    pub fn largest_side(&self) -> Real {
        (0..3).map(|k| self.hi[k] - self.lo[k]).fold(0.0, Real::max)
    }

    pub fn merge(&mut self, o: &Aabb) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(o.lo[k]);
            self.hi[k] = self.hi[k].max(o.hi[k]);
        }
    }

    /// Half the surface area (0 for an empty box).
    pub fn half_area(&self) -> Real {
        let d = [0, 1, 2].map(|k| (self.hi[k] - self.lo[k]).max(0.0));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }
}

/// A node of the flat array: a leaf holds `count > 0` triangles from
/// `first`; an inner node (`count == 0`) has its left child right after it
/// and its right child at `first`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

/// Builds the nodes over the boxes `boxes` (one per triangle); returns the
/// nodes and the leaf order (a permutation of triangle indices).
pub(crate) fn build(boxes: &[Aabb]) -> (Vec<Node>, Vec<u32>) {
    let centroids: Vec<[Real; 3]> = boxes
        .iter()
        .map(|b| [0, 1, 2].map(|k| 0.5 * (b.lo[k] + b.hi[k])))
        .collect();
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    let mut nodes: Vec<Node> = Vec::with_capacity(boxes.len());
    subtree(
        &Input {
            boxes,
            centroids: &centroids,
        },
        &mut order,
        0,
        0,
        &mut nodes,
    );
    (nodes, order)
}

/// Subtrees over at least this many triangles build their two children in
/// parallel; the layout and the splits are those of the serial build.
const PARALLEL_BUILD: usize = 8192;

/// The triangles' boxes and their centroids.
struct Input<'a> {
    boxes: &'a [Aabb],
    centroids: &'a [[Real; 3]],
}

/// Appends to `out` the subtree over `order` (the triangles from `start` of
/// the leaf order) in depth-first layout: a node, its left subtree, its
/// right subtree, an inner node's `first` indexing `out`.
fn subtree(input: &Input, order: &mut [u32], start: usize, depth: usize, out: &mut Vec<Node>) {
    let mut bounds = Aabb::EMPTY;
    let mut cbounds = Aabb::EMPTY;
    for &t in order.iter() {
        bounds.merge(&input.boxes[t as usize]);
        cbounds.grow(&input.centroids[t as usize]);
    }
    let n = order.len();
    let node = out.len();
    out.push(Node {
        bounds,
        first: start as u32,
        count: n as u32,
    });
    let split = if n <= 1 {
        None
    } else {
        choose_split(
            order,
            input.centroids,
            input.boxes,
            &bounds,
            &cbounds,
            depth,
        )
    };
    let Some(mid) = split else { return };
    out[node].count = 0;
    let (left, right) = order.split_at_mut(mid);
    if n < PARALLEL_BUILD {
        subtree(input, left, start, depth + 1, out);
        out[node].first = out.len() as u32;
        subtree(input, right, start + mid, depth + 1, out);
        return;
    }
    let part = |o: &mut [u32], s: usize| {
        let mut nodes = Vec::with_capacity(2 * o.len() / MAX_LEAF);
        subtree(input, o, s, depth + 1, &mut nodes);
        nodes
    };
    let (l, r) = rayon::join(|| part(left, start), || part(right, start + mid));
    let append = |out: &mut Vec<Node>, sub: Vec<Node>| {
        let base = out.len() as u32;
        out.extend(sub.into_iter().map(|mut x| {
            if x.count == 0 {
                x.first += base;
            }
            x
        }));
    };
    append(out, l);
    out[node].first = out.len() as u32;
    append(out, r);
}

/// Partitions `order` at its centroid median along `axis`; returns the
/// size of the left part.
fn median_split(order: &mut [u32], centroids: &[[Real; 3]], axis: usize) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&x, &y| {
        centroids[x as usize][axis].total_cmp(&centroids[y as usize][axis])
    });
    mid
}

/// Partitions `order` and returns the size of the left part, or `None` for a leaf.
fn choose_split(
    order: &mut [u32],
    centroids: &[[Real; 3]],
    boxes: &[Aabb],
    bounds: &Aabb,
    cbounds: &Aabb,
    depth: usize,
) -> Option<usize> {
    let n = order.len();
    let extent = [0, 1, 2].map(|k| cbounds.hi[k] - cbounds.lo[k]);
    let axis = (0..3).fold(0, |a, k| if extent[k] > extent[a] { k } else { a });
    if extent[axis] <= 0.0 || depth >= MEDIAN_DEPTH {
        if n <= MAX_LEAF {
            return None;
        }
        return Some(median_split(order, centroids, axis));
    }
    let scale = BINS as Real / extent[axis];
    let bin_of = |t: u32| {
        let x = (centroids[t as usize][axis] - cbounds.lo[axis]) * scale;
        (x as usize).min(BINS - 1)
    };
    let mut bin_box = [Aabb::EMPTY; BINS];
    let mut bin_count = [0usize; BINS];
    for &t in order.iter() {
        let b = bin_of(t);
        bin_box[b].merge(&boxes[t as usize]);
        bin_count[b] += 1;
    }
    // Sweep from the right: area and count of bins i.. .
    let mut right_area = [0.0; BINS];
    let mut right_count = [0usize; BINS];
    let mut acc = Aabb::EMPTY;
    let mut cnt = 0;
    for i in (1..BINS).rev() {
        acc.merge(&bin_box[i]);
        cnt += bin_count[i];
        right_area[i] = acc.half_area();
        right_count[i] = cnt;
    }
    let mut best = (Real::INFINITY, 0usize);
    let mut acc = Aabb::EMPTY;
    let mut cnt = 0;
    for i in 1..BINS {
        acc.merge(&bin_box[i - 1]);
        cnt += bin_count[i - 1];
        if cnt == 0 || right_count[i] == 0 {
            continue;
        }
        let cost = acc.half_area() * cnt as Real + right_area[i] * right_count[i] as Real;
        if cost < best.0 {
            best = (cost, i);
        }
    }
    let parent_area = bounds.half_area().max(Real::MIN_POSITIVE);
    let split_cost = 1.0 + TRI_COST * best.0 / parent_area;
    let leaf_cost = TRI_COST * n as Real;
    if best.0.is_infinite() || (n <= MAX_LEAF && split_cost >= leaf_cost) {
        if n <= MAX_LEAF {
            return None;
        }
        return Some(median_split(order, centroids, axis));
    }
    let split_bin = best.1;
    let mut i = 0;
    let mut j = n;
    while i < j {
        if bin_of(order[i]) < split_bin {
            i += 1;
        } else {
            j -= 1;
            order.swap(i, j);
        }
    }
    Some(i)
}

//! Closest points on a [`TriangleBvh`]: branch and bound over the 4-wide
//! tree. The four child boxes' squared distances are computed together in
//! `f32` and compared with a conservative bound ([`box_bound`]), children
//! are visited nearest first, and a box that cannot hold a triangle nearer
//! than the best so far is skipped; leaves use Ericson's exact point–triangle
//! test in `f64` ([`PreparedTriangle`], Ericson, *Real-Time Collision
//! Detection*, 2005, §5.1.5), so the answer is exact up to `f64` rounding.

use crate::math::{Point3, Real};

use super::bvh::{Nearest, STACK, TriangleBvh, ascending};
use super::bvh_collapse::Node4;
#[cfg(doc)]
use super::triangle::PreparedTriangle;

impl TriangleBvh {
    /// The point of the mesh closest to `q`, exactly (up to rounding); `None`
    /// only when `q` has a non-finite coordinate. Ties go to the triangle
    /// found first.
    pub fn closest_point(&self, q: Point3) -> Option<Nearest> {
        self.closest_point_from(q, None).map(|(n, _)| n)
    }

    /// [`closest_point`](Self::closest_point) starting from the bound given
    /// by leaf slot `hint` (the previous query's answer in a coherent batch);
    /// also returns the answer's slot.
    pub(crate) fn closest_point_from(
        &self,
        q: Point3,
        hint: Option<usize>,
    ) -> Option<(Nearest, usize)> {
        if !q.coords.iter().all(|c| c.is_finite()) {
            return None;
        }
        let qr = [
            q.x - self.origin[0],
            q.y - self.origin[1],
            q.z - self.origin[2],
        ];
        let far = qr.iter().fold(self.extent, |m, c| m.max(c.abs()));
        // Squared distances are compared as |(p − q) · scale|², scale a power
        // of two (exact) that keeps them finite for any finite input.
        let scale = if far > 1e150 {
            (2.0 as Real).powi(-(far.log2().ceil() as i32))
        } else {
            1.0
        };
        let mut best_d2 = Real::INFINITY;
        let mut best: Option<(usize, Point3, [Real; 3])> = None;
        let mut visit = |slot: usize, best_d2: &mut Real| {
            let (p, bary) = self.leaf_triangles[slot].closest_point(q);
            let d2 = ((p - q) * scale).norm_squared();
            if d2 < *best_d2 {
                *best_d2 = d2;
                best = Some((slot, p, bary));
            }
        };
        if far > F32_SAFE {
            // Beyond what f32 box distances can square: test every triangle.
            for slot in 0..self.leaf_triangles.len() {
                visit(slot, &mut best_d2);
            }
        } else {
            if let Some(slot) = hint {
                visit(slot, &mut best_d2);
            }
            let q32 = qr.map(|c| c as f32);
            let q_err = (0..3)
                .map(|k| (qr[k] - Real::from(q32[k])).powi(2))
                .sum::<Real>()
                .sqrt();
            let mut bound = box_bound(best_d2, q_err);
            // Children are pushed farthest first, leaves included, so the
            // nearest box of all those pending is always the next one opened.
            let mut stack_node = [0u32; STACK];
            let mut stack_count = [0u32; STACK];
            let mut stack_d2 = [0.0f32; STACK];
            let mut top = 1usize;
            while top > 0 {
                top -= 1;
                if stack_d2[top] >= bound {
                    continue;
                }
                let (child, count) = (stack_node[top] as usize, stack_count[top] as usize);
                if count > 0 {
                    let before = best_d2;
                    for slot in child..child + count {
                        visit(slot, &mut best_d2);
                    }
                    if best_d2 < before {
                        bound = box_bound(best_d2, q_err);
                    }
                    continue;
                }
                let n = &self.nodes[child];
                let d2 = child_distances2(n, &q32);
                for &i in ascending(&d2).iter().rev() {
                    if d2[i] < bound {
                        stack_node[top] = n.child[i];
                        stack_count[top] = n.count[i];
                        stack_d2[top] = d2[i];
                        top += 1;
                    }
                }
            }
        }
        best.map(|(slot, point, bary)| {
            (
                Nearest {
                    point,
                    distance: best_d2.sqrt() / scale,
                    triangle: self.leaf_ids[slot] as usize,
                    bary,
                },
                slot,
            )
        })
    }
}

/// Coordinates (relative to the tree's origin) up to which `f32` squared
/// box distances cannot overflow.
const F32_SAFE: Real = 1e18;

/// The `f32` bound that a child box's computed squared distance must stay
/// below to be visited: a box may hold a triangle nearer than `√best_d2`
/// only if its distance from the rounded query is below `√best_d2 + q_err`;
/// the computed `f32` squared distance is within 4 ulp (≈ 5·10⁻⁷ relative)
/// of the exact one, so a margin of 10⁻⁵ keeps the test conservative.
#[inline]
fn box_bound(best_d2: Real, q_err: Real) -> f32 {
    if best_d2.is_infinite() {
        return f32::INFINITY;
    }
    let b = (best_d2.sqrt() + q_err) * (1.0 + 1e-5);
    ((b * b) as f32).next_up()
}

/// Squared distances from `q` (relative to the tree's origin, rounded to
/// `f32`) to the four child boxes of `n`, in `f32`, four lanes at a time
/// (infinite for an empty slot, so it is never pushed). Plain comparisons,
/// not `f32::max` (whose NaN rule costs instructions): inputs are never NaN.
#[inline]
#[allow(clippy::needless_range_loop)] // lane loops over `[axis][child]` arrays vectorise
fn child_distances2(n: &Node4, q: &[f32; 3]) -> [f32; 4] {
    let mut d2 = [0.0f32; 4];
    for k in 0..3 {
        for i in 0..4 {
            let below = n.lo[k][i] - q[k];
            let above = q[k] - n.hi[k][i];
            let d = if below > above { below } else { above };
            let d = if d > 0.0 { d } else { 0.0 };
            d2[i] += d * d;
        }
    }
    d2
}

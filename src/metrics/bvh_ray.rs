//! Ray casts on a [`TriangleBvh`]: front-to-back traversal of the 4-wide
//! tree with a robust slab test (the far bound widened by `1 + 2γ₃`, Ize,
//! "Robust BVH ray traversal", *JCGT* 2(2), 2013) and Möller–Trumbore leaves
//! ([`ray_triangle`]).

use crate::math::{Point3, Real, Vector3};

use super::bvh::{Hit, STACK, TriangleBvh, ascending};
use super::bvh_collapse::EMPTY;
use super::triangle::ray_triangle;

impl TriangleBvh {
    /// The first triangle hit by the ray `origin + t · dir`, `0 ≤ t ≤ t_max`
    /// (pass `Real::INFINITY` for an unbounded ray; `dir` need not be unit and
    /// `t` is in units of `|dir|`). Both triangle sides count. `None` when
    /// nothing is hit, or `dir` is zero, or an input is not finite (`t_max`
    /// may be infinite). Robustness rules of the leaf test: [`ray_triangle`].
    ///
    /// ```
    /// use subdyn::math::{Point3, Vector3};
    /// use subdyn::metrics::TriangleBvh;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// // Two triangles sharing the edge (1,0,0)–(0,1,0) of the unit square z = 0.
    /// let bvh = TriangleBvh::new(
    ///     vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(1., 1., 0.)],
    ///     vec![[0, 1, 2], [1, 3, 2]],
    /// )?;
    /// // A ray straight through the shared edge still hits.
    /// let hit = bvh.ray_cast(p(0.5, 0.5, 2.0), -Vector3::z(), f64::INFINITY).unwrap();
    /// assert_eq!(hit.t, 2.0);
    /// // The hit is reported in the triangle's barycentric coordinates.
    /// let [a, b, c] = bvh.triangles()[hit.triangle].map(|v| bvh.positions()[v as usize]);
    /// let at = Point3::from(a.coords * hit.bary[0] + b.coords * hit.bary[1] + c.coords * hit.bary[2]);
    /// assert!((at - p(0.5, 0.5, 0.0)).norm() < 1e-15);
    /// // Bounded rays stop at t_max.
    /// assert!(bvh.ray_cast(p(0.5, 0.5, 2.0), -Vector3::z(), 1.5).is_none());
    /// # Ok::<(), subdyn::Error>(())
    /// ```
    pub fn ray_cast(&self, origin: Point3, dir: Vector3, t_max: Real) -> Option<Hit> {
        let finite = |v: &Vector3| v.iter().all(|c| c.is_finite());
        if !finite(&origin.coords) || !finite(&dir) || dir == Vector3::zeros() || t_max.is_nan() {
            return None;
        }
        let inv = dir.map(|d| 1.0 / d);
        let o = Vector3::new(
            origin.x - self.origin[0],
            origin.y - self.origin[1],
            origin.z - self.origin[2],
        );
        let mut t_best = t_max;
        let mut best: Option<(usize, Real, [Real; 3])> = None;
        let mut stack_node = [0u32; STACK];
        let mut stack_t = [0.0 as Real; STACK];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            if stack_t[top] > t_best {
                continue;
            }
            let n = &self.nodes[stack_node[top] as usize];
            let t = [0, 1, 2, 3].map(|i| {
                if n.child[i] == EMPTY {
                    return Real::INFINITY;
                }
                let lo = [0, 1, 2].map(|k| Real::from(n.lo[k][i]));
                let hi = [0, 1, 2].map(|k| Real::from(n.hi[k][i]));
                slab(&lo, &hi, &o, &dir, &inv, t_best).unwrap_or(Real::INFINITY)
            });
            let order = ascending(&t.map(|x| x as f32));
            for &i in &order {
                // Never NaN: a slab test gives a finite entry, or +∞ for a
                // missed box. Missed boxes sort last and must stop the scan
                // even while nothing has been hit (t_best = +∞).
                if !t[i].is_finite() || t[i] > t_best {
                    break;
                }
                let first = n.child[i] as usize;
                for slot in first..first + n.count[i] as usize {
                    let [a, b, c] = self.leaf_corners[slot];
                    if let Some((t, bary)) = ray_triangle(origin, dir, t_best, a, b, c)
                        && best.is_none_or(|(_, tb, _)| t < tb)
                    {
                        t_best = t;
                        best = Some((slot, t, bary));
                    }
                }
            }
            for &i in order.iter().rev() {
                if n.count[i] == 0 && n.child[i] != EMPTY && t[i].is_finite() && t[i] <= t_best {
                    stack_node[top] = n.child[i];
                    stack_t[top] = t[i];
                    top += 1;
                }
            }
        }
        best.map(|(slot, t, bary)| Hit {
            t,
            triangle: self.leaf_ids[slot] as usize,
            bary,
        })
    }
}

/// Entry parameter of the ray into the box when it meets the box within
/// `[0, t_max]`. Axes the ray is parallel to are tested by containment; the
/// far bound is widened by `1 + 2γ₃` (Ize 2013) so rounding never culls a
/// box the ray touches.
#[inline]
fn slab(
    lo: &[Real; 3],
    hi: &[Real; 3],
    o: &Vector3,
    dir: &Vector3,
    inv: &Vector3,
    t_max: Real,
) -> Option<Real> {
    const WIDEN: Real = 1.0 + 2.0 * (3.0 * Real::EPSILON / 2.0) / (1.0 - 3.0 * Real::EPSILON / 2.0);
    let mut t0: Real = 0.0;
    let mut t1 = t_max;
    for k in 0..3 {
        if dir[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let a = (lo[k] - o[k]) * inv[k];
        let c = (hi[k] - o[k]) * inv[k];
        let (near, far) = if a <= c { (a, c) } else { (c, a) };
        t0 = t0.max(near);
        t1 = t1.min(far * WIDEN);
    }
    (t0 <= t1).then_some(t0)
}

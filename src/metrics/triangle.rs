//! Point–triangle and ray–triangle primitives: the exact leaf tests of the
//! [`TriangleBvh`](super::TriangleBvh).

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

/// Closest point to `p` on the triangle `abc` (boundary and interior), with
/// its barycentric coordinates `[u, v, w]`: point `= u a + v b + w c`,
/// `u + v + w = 1`, all `≥ 0`.
///
/// The Voronoi-region method of Ericson, *Real-Time Collision Detection*
/// (Morgan Kaufmann 2005), §5.1.5 `ClosestPtPointTriangle`: the vertex
/// regions of `a`, `b`, `c`, then the edge regions of `ab`, `ac`, `bc`, tested
/// with the six dot products `d1 … d6`, and otherwise the projection onto the
/// plane. Implemented by [`PreparedTriangle`], which needs two dot products
/// per query. A degenerate (zero-area) triangle falls back to the closest of
/// its three edges, so the answer is always finite for finite input.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::closest_point_on_triangle;
/// let (a, b, c) = (Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0));
/// let (q, bary) = closest_point_on_triangle(Point3::new(0.25, 0.25, 2.0), a, b, c);
/// assert_eq!(q, Point3::new(0.25, 0.25, 0.0));
/// assert!((bary[0] - 0.5).abs() < 1e-15);
/// let (q, _) = closest_point_on_triangle(Point3::new(2.0, -1.0, 0.0), a, b, c);
/// assert_eq!(q, b); // vertex region of b
/// ```
pub fn closest_point_on_triangle(
    p: Point3,
    a: Point3,
    b: Point3,
    c: Point3,
) -> (Point3, [Real; 3]) {
    PreparedTriangle::new(a, b, c).closest_point(p)
}

/// A triangle prepared for many closest-point queries (Ericson 2005, §5.1.5,
/// with the six dot products rewritten through the Gram matrix of the edges).
///
/// With `ab = b − a`, `ac = c − a` and `ap = p − a`, only `d1 = ab·ap` and
/// `d2 = ac·ap` depend on `p`; Ericson's other four are
/// `d3 = d1 − ab·ab`, `d4 = d2 − ab·ac`, `d5 = d1 − ab·ac`, `d6 = d2 − ac·ac`,
/// and his barycentric numerators become `vc = |ab|² d2 − (ab·ac) d1`,
/// `vb = |ac|² d1 − (ab·ac) d2`, `va = |ab × ac|² − vb − vc`.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::PreparedTriangle;
/// let t = PreparedTriangle::new(Point3::origin(), Point3::new(2.0, 0.0, 0.0), Point3::new(0.0, 2.0, 0.0));
/// let (q, bary) = t.closest_point(Point3::new(2.0, 2.0, 1.0)); // edge bc
/// assert_eq!(q, Point3::new(1.0, 1.0, 0.0));
/// assert_eq!(bary, [0.0, 0.5, 0.5]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedTriangle {
    a: Point3,
    ab: Vector3,
    ac: Vector3,
    /// `|ab|²`, `ab·ac`, `|ac|²`, `|c − b|²`, `|ab × ac|²`.
    gram: [Real; 5],
}

impl PreparedTriangle {
    /// Precomputes the edges and their Gram matrix.
    pub fn new(a: Point3, b: Point3, c: Point3) -> Self {
        let (ab, ac) = (b - a, c - a);
        let gram = [
            ab.norm_squared(),
            ab.dot(&ac),
            ac.norm_squared(),
            (c - b).norm_squared(),
            ab.cross(&ac).norm_squared(),
        ];
        PreparedTriangle { a, ab, ac, gram }
    }

    /// The closest point to `p` and its barycentric coordinates (see
    /// [`closest_point_on_triangle`]).
    #[inline]
    pub fn closest_point(&self, p: Point3) -> (Point3, [Real; 3]) {
        let [aa, bc, cc, edge_bc, area2] = self.gram;
        let (a, ab, ac) = (self.a, self.ab, self.ac);
        if !(area2 > 0.0 && area2.is_finite()) {
            return closest_on_edges(p, a, a + ab, a + ac);
        }
        let ap = p - a;
        let d1 = ab.dot(&ap);
        let d2 = ac.dot(&ap);
        if d1 <= 0.0 && d2 <= 0.0 {
            return (a, [1.0, 0.0, 0.0]);
        }
        let (d3, d4) = (d1 - aa, d2 - bc);
        if d3 >= 0.0 && d4 <= d3 {
            return (a + ab, [0.0, 1.0, 0.0]);
        }
        let vc = aa * d2 - bc * d1;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let v = d1 / aa; // d1 / (d1 − d3)
            return (a + ab * v, [1.0 - v, v, 0.0]);
        }
        let (d5, d6) = (d1 - bc, d2 - cc);
        if d6 >= 0.0 && d5 <= d6 {
            return (a + ac, [0.0, 0.0, 1.0]);
        }
        let vb = cc * d1 - bc * d2;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let w = d2 / cc; // d2 / (d2 − d6)
            return (a + ac * w, [1.0 - w, 0.0, w]);
        }
        let va = area2 - vb - vc;
        let (e, f) = (d4 - d3, d5 - d6);
        if va <= 0.0 && e >= 0.0 && f >= 0.0 {
            let w = (e / edge_bc).clamp(0.0, 1.0); // e / (e + f)
            return (a + ab * (1.0 - w) + ac * w, [0.0, 1.0 - w, w]);
        }
        let v = vb / area2;
        let w = vc / area2;
        let u = (va / area2).max(0.0);
        (a + ab * v + ac * w, [u, v.max(0.0), w.max(0.0)])
    }
}

/// The closest point of the three edges of a degenerate triangle.
fn closest_on_edges(p: Point3, a: Point3, b: Point3, c: Point3) -> (Point3, [Real; 3]) {
    let on = |s: Point3, t: Point3| {
        let st = t - s;
        let len2 = st.norm_squared();
        let x = if len2 > 0.0 {
            ((p - s).dot(&st) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (s + st * x, x)
    };
    let (pab, x) = on(a, b);
    let (pbc, y) = on(b, c);
    let (pca, z) = on(c, a);
    let candidates = [
        (pab, [1.0 - x, x, 0.0]),
        (pbc, [0.0, 1.0 - y, y]),
        (pca, [z, 0.0, 1.0 - z]),
    ];
    let mut best = candidates[0];
    for cand in &candidates[1..] {
        if (cand.0 - p).norm_squared() < (best.0 - p).norm_squared() {
            best = *cand;
        }
    }
    best
}

/// Barycentric slack of [`ray_triangle`]: a hit may lie this far outside the
/// triangle in barycentric units, so a ray through a shared edge cannot slip
/// between the two triangles through rounding.
pub const RAY_BARY_SLACK: Real = 1e-12;

/// Rays within this angle (radians, as `|cos|` of the angle to the plane)
/// of a triangle's plane are treated as parallel to it and miss.
pub const RAY_PARALLEL_COS: Real = 1e-12;

/// Ray–triangle intersection, Möller & Trumbore, "Fast, minimum storage
/// ray-triangle intersection", *Journal of Graphics Tools* 2(1), 1997.
///
/// The ray is `origin + t dir`, `0 ≤ t ≤ t_max` (`dir` need not be unit;
/// `t` is in units of `|dir|`). Returns `(t, [u, v, w])` with the hit at
/// `u a + v b + w c`. Both faces count (no culling). Robustness: a ray within
/// [`RAY_PARALLEL_COS`] of the plane misses (its hit would be ill-conditioned);
/// barycentric tests are widened by [`RAY_BARY_SLACK`] so shared edges and
/// vertices are never cracks.
///
/// ```
/// use subdyn::math::{Point3, Vector3};
/// use subdyn::metrics::ray_triangle;
/// let (a, b, c) = (Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0));
/// let hit = ray_triangle(Point3::new(0.2, 0.2, 1.0), Vector3::new(0.0, 0.0, -2.0), f64::INFINITY, a, b, c);
/// let (t, bary) = hit.unwrap();
/// assert!((t - 0.5).abs() < 1e-15 && (bary[1] - 0.2).abs() < 1e-15);
/// ```
#[inline]
pub fn ray_triangle(
    origin: Point3,
    dir: Vector3,
    t_max: Real,
    a: Point3,
    b: Point3,
    c: Point3,
) -> Option<(Real, [Real; 3])> {
    let e1 = b - a;
    let e2 = c - a;
    let pvec = dir.cross(&e2);
    let det = e1.dot(&pvec);
    // |det| = |dir| |e1 × e2| |cos θ|, θ the angle between dir and the normal.
    let scale = dir.norm() * e1.cross(&e2).norm();
    if det.abs() <= RAY_PARALLEL_COS * scale || det.abs() == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tvec = origin - a;
    let u = tvec.dot(&pvec) * inv;
    if !(-RAY_BARY_SLACK..=1.0 + RAY_BARY_SLACK).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(&e1);
    let v = dir.dot(&qvec) * inv;
    if v < -RAY_BARY_SLACK || u + v > 1.0 + RAY_BARY_SLACK {
        return None;
    }
    let t = e2.dot(&qvec) * inv;
    if !(t >= 0.0 && t <= t_max) {
        return None;
    }
    Some((t, [1.0 - u - v, u, v]))
}

/// Unit normal of triangle `abc` (`(b − a) × (c − a)` normalised; zero for a
/// degenerate triangle).
pub fn triangle_normal(a: Point3, b: Point3, c: Point3) -> Vector3 {
    (b - a)
        .cross(&(c - a))
        .try_normalize(0.0)
        .unwrap_or_else(Vector3::zeros)
}

/// Checks triangles (indices into `positions`) for the structures built
/// over them: at most `u32::MAX` triangles, finite positions, every index
/// in range.
pub(crate) fn check_triangles(positions: &[Point3], triangles: &[[u32; 3]]) -> Result<()> {
    if triangles.len() > u32::MAX as usize {
        return Err(Error::input(format!(
            "{} triangles: at most {} are supported",
            triangles.len(),
            u32::MAX
        )));
    }
    crate::mesh::check_finite(positions)?;
    let n = positions.len();
    if let Some((t, tri)) = triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&v| v as usize >= n))
    {
        return Err(Error::input(format!(
            "triangle {t} refers to vertex {}, but there are only {n} vertices",
            tri.iter().copied().max().unwrap_or(0)
        )));
    }
    Ok(())
}

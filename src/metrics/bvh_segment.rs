//! Segment queries on a [`TriangleBvh`], and its self-intersections
//! (found by the grid of [`super::self_intersections`]).

use crate::math::{Point3, Real, Vector3};

use super::bvh::{STACK, TriangleBvh};
use super::bvh_collapse::EMPTY;
use super::bvh_ray::slab;
use super::self_intersections::pairs_of;
use super::triangle::ray_triangle;

impl TriangleBvh {
    /// Appends to `out` every triangle (index into
    /// [`triangles`](Self::triangles)) the closed segment `a`–`b` crosses or
    /// touches, in no particular order. Nothing for a zero-length or
    /// non-finite segment.
    ///
    /// ```
    /// use subdyn::math::Point3;
    /// use subdyn::metrics::TriangleBvh;
    /// let cube = subdyn::examples::cube();
    /// let bvh = TriangleBvh::from_mesh(&cube)?;
    /// let mut hits = Vec::new();
    /// // A segment through the cube from below to above crosses z = 0 and z = 1.
    /// bvh.segment_hits(Point3::new(0.3, 0.6, -1.0), Point3::new(0.3, 0.6, 2.0), &mut hits);
    /// let mut faces: Vec<usize> = hits.iter().map(|&t| bvh.face_of(t)).collect();
    /// faces.sort();
    /// assert_eq!(faces.len(), 2);
    /// # Ok::<(), subdyn::Error>(())
    /// ```
    pub fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<usize>) {
        let Some((a, dir)) = segment(a, b) else {
            return;
        };
        let inv = dir.map(|d| 1.0 / d);
        let o = Vector3::new(
            a.x - self.origin[0],
            a.y - self.origin[1],
            a.z - self.origin[2],
        );
        self.walk(
            |lo, hi| slab(lo, hi, &o, &dir, &inv, 1.0).is_some(),
            |slots| {
                for slot in slots {
                    let [p, q, r] = self.leaf_corners[slot];
                    if ray_triangle(a, dir, 1.0, p, q, r).is_some() {
                        out.push(self.leaf_ids[slot] as usize);
                    }
                }
            },
        );
    }

    /// The pairs `[s, t]` (`s < t`, sorted) of triangles that share no
    /// vertex index and intersect (module docs). On a closed tessellated
    /// surface, any pair is a place where the surface passes through itself:
    /// a fold, a pinch or two parts grown into each other.
    ///
    /// ```
    /// use subdyn::math::Point3;
    /// use subdyn::metrics::TriangleBvh;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// // Two triangles crossing like the arms of an X, and one far away.
    /// let bvh = TriangleBvh::new(
    ///     vec![p(0., 0., 0.), p(2., 0., 0.), p(1., 2., 0.),
    ///          p(1., 1., -1.), p(1., 1., 1.), p(1., -1., 0.5),
    ///          p(9., 9., 9.), p(10., 9., 9.), p(9., 10., 9.)],
    ///     vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
    /// )?;
    /// assert_eq!(bvh.self_intersections(), vec![[0, 1]]);
    /// # Ok::<(), subdyn::Error>(())
    /// ```
    pub fn self_intersections(&self) -> Vec<[u32; 2]> {
        pairs_of(self.positions(), self.triangles())
    }

    /// Walks the tree depth first into every child whose box (relative to
    /// the tree's origin) `enter` accepts, handing each accepted leaf's slot
    /// range to `leaf`.
    fn walk(
        &self,
        enter: impl Fn(&[Real; 3], &[Real; 3]) -> bool,
        mut leaf: impl FnMut(std::ops::Range<usize>),
    ) {
        let mut stack = [0u32; STACK];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let n = &self.nodes[stack[top] as usize];
            for i in 0..4 {
                if n.child[i] == EMPTY {
                    continue;
                }
                let lo = [0, 1, 2].map(|k| Real::from(n.lo[k][i]));
                let hi = [0, 1, 2].map(|k| Real::from(n.hi[k][i]));
                if !enter(&lo, &hi) {
                    continue;
                }
                let first = n.child[i] as usize;
                if n.count[i] == 0 {
                    stack[top] = n.child[i];
                    top += 1;
                } else {
                    leaf(first..first + n.count[i] as usize);
                }
            }
        }
    }
}

/// The segment `a`–`b` as origin and direction, `None` when it has no
/// length or is not finite.
fn segment(a: Point3, b: Point3) -> Option<(Point3, Vector3)> {
    let dir = b - a;
    let finite = |v: &Vector3| v.iter().all(|c| c.is_finite());
    (finite(&a.coords) && finite(&dir) && dir != Vector3::zeros()).then_some((a, dir))
}

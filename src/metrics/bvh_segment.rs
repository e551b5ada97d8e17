//! Segment queries and self-intersections on a [`TriangleBvh`].
//!
//! Two triangles that are not coplanar intersect exactly when an edge of
//! one crosses the other (Möller, "A fast triangle-triangle intersection
//! test", *JGT* 2(2), 1997, §2: the intersection segment of the two planes
//! is bounded by edge crossings). So the pairs of a mesh's triangles that
//! share no vertex and intersect, the pairs Open3D's
//! `get_self_intersecting_triangles()` reports, are found by casting every
//! triangle edge as a segment through the hierarchy: `O(n log n)` instead of
//! the `n²` pair tests. Coplanar overlaps are not found (the crossing test
//! [`ray_triangle`] skips segments parallel to a triangle).

use rayon::prelude::*;

use crate::math::{Point3, Vector3};

use super::bvh::{STACK, TriangleBvh};
use super::bvh_collapse::EMPTY;
use super::bvh_ray::slab;
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
        let dir = b - a;
        let finite = |v: &Vector3| v.iter().all(|c| c.is_finite());
        if !finite(&a.coords) || !finite(&dir) || dir == Vector3::zeros() {
            return;
        }
        let inv = dir.map(|d| 1.0 / d);
        let o = Vector3::new(
            a.x - self.origin[0],
            a.y - self.origin[1],
            a.z - self.origin[2],
        );
        let mut stack = [0u32; STACK];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let n = &self.nodes[stack[top] as usize];
            for i in 0..4 {
                if n.child[i] == EMPTY {
                    continue;
                }
                let lo = [0, 1, 2].map(|k| f64::from(n.lo[k][i]));
                let hi = [0, 1, 2].map(|k| f64::from(n.hi[k][i]));
                if slab(&lo, &hi, &o, &dir, &inv, 1.0).is_none() {
                    continue;
                }
                if n.count[i] == 0 {
                    stack[top] = n.child[i];
                    top += 1;
                    continue;
                }
                let first = n.child[i] as usize;
                for slot in first..first + n.count[i] as usize {
                    let [p, q, r] = self.leaf_corners[slot];
                    if ray_triangle(a, dir, 1.0, p, q, r).is_some() {
                        out.push(self.leaf_ids[slot] as usize);
                    }
                }
            }
        }
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
        let tris = self.triangles();
        // Every edge once, with the (one or two) triangles it bounds.
        let mut edges: Vec<([u32; 2], u32)> = tris
            .iter()
            .enumerate()
            .flat_map(|(t, v)| {
                (0..3).map(move |e| {
                    let (a, b) = (v[e], v[(e + 1) % 3]);
                    ([a.min(b), a.max(b)], t as u32)
                })
            })
            .collect();
        edges.par_sort_unstable();
        let runs: Vec<&[([u32; 2], u32)]> = edges.chunk_by(|x, y| x.0 == y.0).collect();
        let mut pairs: Vec<[u32; 2]> = runs
            .into_par_iter()
            .flat_map_iter(|run| {
                let [a, b] = run[0].0;
                let mut hits = Vec::new();
                self.segment_hits(
                    self.positions()[a as usize],
                    self.positions()[b as usize],
                    &mut hits,
                );
                run.iter().flat_map(move |&(_, s)| {
                    let t = tris[s as usize];
                    hits.clone()
                        .into_iter()
                        .filter(move |&h| !tris[h].iter().any(|v| t.contains(v)))
                        .map(move |h| [s.min(h as u32), s.max(h as u32)])
                })
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }
}

//! Segment queries and self-intersections on a [`TriangleBvh`].
//!
//! Two triangles that are not coplanar intersect exactly when an edge of
//! one crosses the other (Möller, "A fast triangle-triangle intersection
//! test", *JGT* 2(2), 1997, §2: the intersection segment of the two planes
//! is bounded by edge crossings). So the pairs of a mesh's triangles that
//! share no vertex and intersect, the pairs Open3D's
//! `get_self_intersecting_triangles()` reports, are found by testing every
//! triangle's edges against the triangles whose boxes overlap its own. The
//! candidates are gathered once per leaf of the hierarchy, with the leaf's
//! box: `O(n log n)` instead of the `n²` pair tests, and a few traversals
//! per leaf instead of one per edge. Coplanar overlaps are not found (the
//! crossing test [`ray_triangle`] skips segments parallel to a triangle).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

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
        let tris = self.triangles();
        let leaves: Vec<(usize, usize)> = self
            .nodes
            .iter()
            .enumerate()
            .flat_map(|(n, node)| {
                (0..4)
                    .filter(move |&i| node.child[i] != EMPTY && node.count[i] > 0)
                    .map(move |i| (n, i))
            })
            .collect();
        // The boxes are widened by far more than the crossing test's slack
        // (`RAY_BARY_SLACK` of a triangle's size): the candidates are a
        // superset of the triangles an edge can cross.
        let margin = 1e-9 * self.extent.max(Real::MIN_POSITIVE);
        let exact_box = |c: &[Point3; 3]| {
            let lo = [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k]) - margin);
            let hi = [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k]) + margin);
            (lo, hi)
        };
        let mut pairs: Vec<[u32; 2]> = leaves
            .into_par_iter()
            .flat_map_iter(|(n, i)| {
                let node = &self.nodes[n];
                let lo = [0, 1, 2].map(|k| Real::from(node.lo[k][i]) - margin);
                let hi = [0, 1, 2].map(|k| Real::from(node.hi[k][i]) + margin);
                let mut near = Vec::new();
                self.slots_overlapping(&lo, &hi, &mut near);
                let near_boxes: Vec<_> = near
                    .iter()
                    .map(|&other| exact_box(&self.leaf_corners[other]))
                    .collect();
                let first = node.child[i] as usize;
                let mut out = Vec::new();
                for slot in first..first + node.count[i] as usize {
                    let s = self.leaf_ids[slot];
                    let ts = tris[s as usize];
                    // Each edge from its lower vertex index, as every
                    // triangle sharing it sees it.
                    let edges: [Option<(Point3, Vector3)>; 3] = std::array::from_fn(|e| {
                        let [a, b] = edge_from_lower(&ts, e);
                        segment(self.positions()[a as usize], self.positions()[b as usize])
                    });
                    let (slo, shi) = exact_box(&self.leaf_corners[slot]);
                    for (&other, (tlo, thi)) in near.iter().zip(&near_boxes) {
                        let t = self.leaf_ids[other];
                        let [p, q, r] = self.leaf_corners[other];
                        if (0..3).any(|k| tlo[k] > shi[k] || thi[k] < slo[k])
                            || tris[t as usize].iter().any(|v| ts.contains(v))
                        {
                            continue;
                        }
                        if edges
                            .iter()
                            .flatten()
                            .any(|&(a, dir)| ray_triangle(a, dir, 1.0, p, q, r).is_some())
                        {
                            out.push([s.min(t), s.max(t)]);
                        }
                    }
                }
                out
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }

    /// [`self_intersections`](Self::self_intersections) of this hierarchy's
    /// triangles with their vertices at `positions` instead (the same
    /// vertices, some of them moved), given the pairs `pairs` at the
    /// hierarchy's own positions. Only the triangles with a moved vertex are
    /// tested again, against each other, against the others (through this
    /// hierarchy, where the others still are) and the others' edges against
    /// them, so a local change costs about its own size; each test is the
    /// one the full search makes, so the pairs are the same.
    pub fn self_intersections_moved(
        &self,
        pairs: &[[u32; 2]],
        positions: &[Point3],
    ) -> Result<Vec<[u32; 2]>> {
        let tris = self.triangles();
        if positions.len() != self.positions().len() {
            return Err(Error::Input(format!(
                "{} positions for a hierarchy over {} vertices",
                positions.len(),
                self.positions().len()
            )));
        }
        let moved: Vec<bool> = self
            .positions()
            .iter()
            .zip(positions)
            .map(|(a, b)| a != b)
            .collect();
        let changed: Vec<bool> = tris
            .iter()
            .map(|t| t.iter().any(|&v| moved[v as usize]))
            .collect();
        let ids: Vec<u32> = (0..tris.len() as u32)
            .filter(|&t| changed[t as usize])
            .collect();
        let mut out: Vec<[u32; 2]> = pairs
            .iter()
            .filter(|p| !changed[p[0] as usize] && !changed[p[1] as usize])
            .copied()
            .collect();
        if ids.is_empty() {
            return Ok(out);
        }
        let moved_tris = TriangleBvh::new(
            positions.to_vec(),
            ids.iter().map(|&t| tris[t as usize]).collect(),
        )?;
        let pair = |s: u32, t: u32| [s.min(t), s.max(t)];
        out.extend(
            moved_tris
                .self_intersections()
                .into_iter()
                .map(|[a, b]| pair(ids[a as usize], ids[b as usize])),
        );
        // Edges as the full search takes them.
        let edge = |t: &[u32; 3], e: usize| {
            let [a, b] = edge_from_lower(t, e);
            (positions[a as usize], positions[b as usize])
        };
        let shares = |s: &[u32; 3], t: &[u32; 3]| s.iter().any(|v| t.contains(v));
        // Moved edges against the triangles that stayed.
        out.par_extend(ids.par_iter().flat_map_iter(|&s| {
            let ts = &tris[s as usize];
            let mut hits = Vec::new();
            for e in 0..3 {
                let (a, b) = edge(ts, e);
                self.segment_hits(a, b, &mut hits);
            }
            hits.into_iter()
                .filter(|&t| !changed[t] && !shares(ts, &tris[t]))
                .map(move |t| pair(s, t as u32))
        }));
        // Edges of the triangles that stayed against the moved ones, for the
        // triangles near them.
        let margin = 1e-9 * self.extent.max(Real::MIN_POSITIVE);
        let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
        for &t in &ids {
            for &v in &tris[t as usize] {
                for k in 0..3 {
                    lo[k] = lo[k].min(positions[v as usize][k] - margin);
                    hi[k] = hi[k].max(positions[v as usize][k] + margin);
                }
            }
        }
        out.par_extend((0..tris.len() as u32).into_par_iter().flat_map_iter(|t| {
            let tt = &tris[t as usize];
            let near = !changed[t as usize]
                && (0..3).all(|k| {
                    let c = tt.map(|v| positions[v as usize][k]);
                    c.iter().copied().fold(Real::INFINITY, Real::min) <= hi[k]
                        && c.iter().copied().fold(Real::NEG_INFINITY, Real::max) >= lo[k]
                });
            let mut hits = Vec::new();
            if near {
                for e in 0..3 {
                    let (a, b) = edge(tt, e);
                    moved_tris.segment_hits(a, b, &mut hits);
                }
            }
            hits.into_iter()
                .map(|l| ids[l])
                .filter(|&s| !shares(tt, &tris[s as usize]))
                .map(move |s| pair(s, t))
        }));
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }

    /// Appends to `out` every leaf slot whose leaf box overlaps the box
    /// `lo`–`hi` (closed, relative to the tree's origin like the node boxes).
    fn slots_overlapping(&self, lo: &[Real; 3], hi: &[Real; 3], out: &mut Vec<usize>) {
        self.walk(
            |clo, chi| (0..3).all(|k| clo[k] <= hi[k] && chi[k] >= lo[k]),
            |slots| out.extend(slots),
        );
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

/// Edge `e` of triangle `t` from its lower vertex index: every triangle
/// sharing the edge tests the same segment.
fn edge_from_lower(t: &[u32; 3], e: usize) -> [u32; 2] {
    let (a, b) = (t[e], t[(e + 1) % 3]);
    [a.min(b), a.max(b)]
}

/// The segment `a`–`b` as origin and direction, `None` when it has no
/// length or is not finite.
fn segment(a: Point3, b: Point3) -> Option<(Point3, Vector3)> {
    let dir = b - a;
    let finite = |v: &Vector3| v.iter().all(|c| c.is_finite());
    (finite(&a.coords) && finite(&dir) && dir != Vector3::zeros()).then_some((a, dir))
}

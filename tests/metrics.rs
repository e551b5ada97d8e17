//! Metrics: the BVH against brute force (closest points and ray casts, to
//! 1e-12, on random meshes and at vertices and edges), distance statistics on
//! known inputs, `compare` on a mesh with itself and with a shifted copy, and
//! the `subdyn compare` / `subdyn bench distance` verbs end to end.
//!
//! The brute-force closest point is an independent formula — projection onto
//! the plane when it falls inside the triangle, else the nearest of the three
//! edge segments — so the leaf test is checked too, not only the traversal.

mod common;

use common::{assert_clean_failure, run_subdyn};

use std::path::Path;
use std::process::Output;

use serde_json::Value;

use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::metrics::{
    CompareParams, DistanceStats, Surface, TriangleBvh, area_samples, closest_point_on_triangle,
    compare, compare_points, distances, percentile, ray_triangle, self_intersecting_pairs,
};
use subdyn::subdivision::RefineOptions;

// ------------------------------------------------------------------ helpers

/// A deterministic generator of uniform numbers in `[0, 1)` (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> Real {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as Real / (1u64 << 53) as Real
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.next()
    }
    fn point(&mut self, s: Real) -> Point3 {
        Point3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
    fn index(&mut self, n: usize) -> usize {
        ((self.next() * n as Real) as usize).min(n - 1)
    }
}

/// Distance from `p` to the segment `ab`.
fn segment_distance(p: Point3, a: Point3, b: Point3) -> Real {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Independent point–triangle distance: the plane projection when its
/// barycentric coordinates are all non-negative, else the nearest edge.
fn reference_distance(p: Point3, a: Point3, b: Point3, c: Point3) -> Real {
    let n = (b - a).cross(&(c - a));
    let area2 = n.norm_squared();
    if area2 > 0.0 {
        let proj = p - n * ((p - a).dot(&n) / area2);
        let w_a = (b - proj).cross(&(c - proj)).dot(&n) / area2;
        let w_b = (c - proj).cross(&(a - proj)).dot(&n) / area2;
        let w_c = 1.0 - w_a - w_b;
        if w_a >= 0.0 && w_b >= 0.0 && w_c >= 0.0 {
            return (p - proj).norm();
        }
    }
    segment_distance(p, a, b)
        .min(segment_distance(p, b, c))
        .min(segment_distance(p, c, a))
}

/// Brute force over every triangle.
fn brute_distance(bvh: &TriangleBvh, q: Point3) -> Real {
    let p = bvh.positions();
    bvh.triangles()
        .iter()
        .map(|t| reference_distance(q, p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]))
        .fold(Real::INFINITY, Real::min)
}

/// Brute-force first hit: `(t, triangle)`.
fn brute_ray(bvh: &TriangleBvh, o: Point3, d: Vector3) -> Option<(Real, usize)> {
    let p = bvh.positions();
    let mut best: Option<(Real, usize)> = None;
    for (i, t) in bvh.triangles().iter().enumerate() {
        let [a, b, c] = t.map(|v| p[v as usize]);
        if let Some((t, _)) = ray_triangle(o, d, Real::INFINITY, a, b, c)
            && best.is_none_or(|(bt, _)| t < bt)
        {
            best = Some((t, i));
        }
    }
    best
}

/// A triangle soup of `n` random triangles of size about `size` in `[-1, 1]³`.
fn random_soup(rng: &mut Rng, n: usize, size: Real) -> TriangleBvh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..n as u32 {
        let c = rng.point(1.0);
        for _ in 0..3 {
            positions.push(c + rng.point(size).coords);
        }
        triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    TriangleBvh::new(positions, triangles).unwrap()
}

/// An `n × n` grid of unit-square quads on the plane `z = 0` (or `z = h`).
fn grid(n: usize, h: Real) -> PolyMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(Point3::new(i as Real, j as Real, h));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolyMesh::from_faces(positions, &faces).unwrap()
}

/// Queries near and far from `bvh`, plus every vertex and points on edges.
fn queries(rng: &mut Rng, bvh: &TriangleBvh, n: usize) -> Vec<Point3> {
    let mut q: Vec<Point3> = (0..n / 2).map(|_| rng.point(1.2)).collect();
    q.extend((0..n / 4).map(|_| rng.point(10.0)));
    let p = bvh.positions();
    q.extend_from_slice(p);
    for t in bvh.triangles().iter().take(n / 4) {
        let [a, b, c] = t.map(|v| p[v as usize]);
        let s = rng.next();
        q.push(a + (b - a) * s);
        q.push(Point3::from((a.coords + b.coords + c.coords) / 3.0));
        q.push(Point3::from((b.coords + c.coords) * 0.5));
    }
    q
}

// ---------------------------------------------------------------- BVH

#[test]
fn closest_point_matches_brute_force_on_random_soups() {
    let mut rng = Rng(1);
    for (n, size) in [(1, 0.5), (7, 0.3), (60, 0.2), (400, 0.1), (400, 0.02)] {
        let bvh = random_soup(&mut rng, n, size);
        for q in queries(&mut rng, &bvh, 400) {
            let near = bvh.closest_point(q).unwrap();
            let brute = brute_distance(&bvh, q);
            assert!(
                (near.distance - brute).abs() <= 1e-12,
                "n = {n}: BVH {} vs brute {brute} at {q:?}",
                near.distance
            );
            // The reported point, triangle and barycentrics agree with each other.
            assert!(((near.point - q).norm() - near.distance).abs() <= 1e-14);
            let [a, b, c] = bvh.triangles()[near.triangle].map(|v| bvh.positions()[v as usize]);
            let w = near.bary;
            assert!((w[0] + w[1] + w[2] - 1.0).abs() <= 1e-14 && w.iter().all(|&x| x >= 0.0));
            let at = a.coords * w[0] + b.coords * w[1] + c.coords * w[2];
            assert!((at - near.point.coords).norm() <= 1e-14);
        }
    }
}

#[test]
fn closest_point_is_zero_on_vertices_and_edges_of_a_mesh() {
    let torus = subdyn::examples::torus(12, 8, 1.0, 0.3);
    let bvh = TriangleBvh::from_mesh(&torus).unwrap();
    let p = bvh.positions();
    for t in bvh.triangles() {
        let [a, b, c] = t.map(|v| p[v as usize]);
        for q in [a, b, c, Point3::from((a.coords + b.coords) * 0.5)] {
            assert!(bvh.closest_point(q).unwrap().distance <= 1e-15);
        }
    }
    let mut rng = Rng(5);
    for q in queries(&mut rng, &bvh, 600) {
        let d = bvh.closest_point(q).unwrap().distance;
        assert!((d - brute_distance(&bvh, q)).abs() <= 1e-12);
    }
}

#[test]
fn closest_point_is_exact_far_from_the_origin_and_for_far_queries() {
    // Boxes are stored as f32 relative to the tree's centre: a mesh far from
    // the origin, and queries far from the mesh (even beyond the range where
    // f32 squares are finite, which takes the test-every-triangle path), must
    // give exactly what testing every triangle gives. (The plane-projection
    // reference loses digits there, so the brute force here is the leaf test.)
    let brute = |bvh: &TriangleBvh, q: Point3| {
        let p = bvh.positions();
        bvh.triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                let v = closest_point_on_triangle(q, a, b, c).0 - q;
                let m = v.amax();
                if m > 0.0 { m * (v / m).norm() } else { 0.0 } // no overflow at 1e300
            })
            .fold(Real::INFINITY, Real::min)
    };
    let mut rng = Rng(21);
    let soup = random_soup(&mut rng, 200, 0.05);
    let shift = Vector3::new(1e6, -3e6, 2.5e5);
    let moved: Vec<Point3> = soup.positions().iter().map(|p| p + shift).collect();
    let bvh = TriangleBvh::new(moved, soup.triangles().to_vec()).unwrap();
    for _ in 0..300 {
        let q = rng.point(1.1) + shift;
        let (d, b) = (bvh.closest_point(q).unwrap().distance, brute(&bvh, q));
        assert!((d - b).abs() <= 1e-15 * b.max(1.0), "{d} vs {b}");
    }
    let bvh = random_soup(&mut rng, 100, 0.1);
    for scale in [1e3, 1e9, 1e17, 1e20, 1e300] {
        let q = Point3::new(scale, -0.5 * scale, 0.25);
        let d = bvh.closest_point(q).unwrap().distance;
        let b = brute(&bvh, q);
        assert!((d - b).abs() <= 1e-15 * b, "{scale}: {d} vs {b}");
        assert!(
            (d / (1.25f64.sqrt() * scale) - 1.0).abs() < 1e-2,
            "{scale}: {d}"
        );
    }
}

#[test]
fn batch_distances_equal_single_queries_in_input_order() {
    let mut rng = Rng(9);
    let bvh = random_soup(&mut rng, 300, 0.1);
    // More than the Morton-sort threshold, so the sorted path runs.
    let q: Vec<Point3> = (0..10_000).map(|_| rng.point(1.5)).collect();
    let batch = distances(&bvh, &q).unwrap();
    for (qi, b) in q.iter().zip(&batch).step_by(7) {
        assert_eq!(*b, bvh.closest_point(*qi).unwrap());
    }
    let bad = [Point3::origin(), Point3::new(Real::NAN, 0.0, 0.0)];
    let err = distances(&bvh, &bad).unwrap_err().to_string();
    assert!(err.contains("query point 1"), "{err}");
}

#[test]
fn degenerate_triangles_give_finite_answers() {
    let p = |x, y, z| Point3::new(x, y, z);
    // A sliver (collinear), a point triangle, and a normal one.
    let bvh = TriangleBvh::new(
        vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(2., 0., 0.),
            p(5., 5., 5.),
            p(0., 3., 0.),
            p(1., 3., 0.),
            p(0., 4., 0.),
        ],
        vec![[0, 1, 2], [3, 3, 3], [4, 5, 6]],
    )
    .unwrap();
    let mut rng = Rng(3);
    for _ in 0..500 {
        let q = rng.point(6.0);
        let d = bvh.closest_point(q).unwrap().distance;
        assert!(d.is_finite());
        assert!((d - brute_distance(&bvh, q)).abs() <= 1e-12);
    }
    let (x, w) = closest_point_on_triangle(
        p(1.5, 1.0, 0.0),
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(2., 0., 0.),
    );
    assert!((x - p(1.5, 0.0, 0.0)).norm() < 1e-15 && w.iter().all(|v| v.is_finite()));
    // Thousands of copies of one triangle (all centroids equal: median splits).
    let tri = [p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)];
    let copies = TriangleBvh::new(tri.to_vec(), vec![[0, 1, 2]; 5000]).unwrap();
    let near = copies.closest_point(p(0.2, 0.2, 0.5)).unwrap();
    assert_eq!(near.distance, 0.5);
    let hit = copies
        .ray_cast(p(0.2, 0.2, 0.5), -Vector3::z(), 1.0)
        .unwrap();
    assert_eq!(hit.t, 0.5);
}

#[test]
fn bvh_rejects_bad_input() {
    assert!(TriangleBvh::new(vec![Point3::origin()], vec![]).is_err());
    assert!(TriangleBvh::new(vec![Point3::origin(); 3], vec![[0, 1, 3]]).is_err());
    let nan = Point3::new(Real::NAN, 0.0, 0.0);
    assert!(
        TriangleBvh::new(
            vec![nan, Point3::origin(), Point3::origin()],
            vec![[0, 1, 2]]
        )
        .is_err()
    );
    let points_only = PolyMesh::from_faces(vec![Point3::origin(); 4], &[]).unwrap();
    let err = TriangleBvh::from_mesh(&points_only)
        .unwrap_err()
        .to_string();
    assert!(err.contains("no faces"), "{err}");
    let bvh = TriangleBvh::from_mesh(&subdyn::examples::cube()).unwrap();
    assert!(bvh.closest_point(nan).is_none());
    assert!(
        bvh.ray_cast(Point3::origin(), Vector3::zeros(), 1.0)
            .is_none()
    );
}

#[test]
fn ray_cast_matches_brute_force() {
    let mut rng = Rng(11);
    for (n, size) in [(1, 0.8), (50, 0.3), (500, 0.1)] {
        let bvh = random_soup(&mut rng, n, size);
        let mut hits = 0;
        for _ in 0..2000 {
            let o = rng.point(2.0);
            // Rays aimed at a random vertex (so many hit), or random.
            let target = bvh.positions()[rng.index(bvh.positions().len())] + rng.point(0.05).coords;
            let d = if rng.next() < 0.7 {
                target - o
            } else {
                rng.point(1.0).coords
            };
            let got = bvh.ray_cast(o, d, Real::INFINITY);
            let want = brute_ray(&bvh, o, d);
            match (got, want) {
                (Some(h), Some((t, _))) => {
                    assert!((h.t - t).abs() <= 1e-12 * t.max(1.0), "t {} vs {t}", h.t);
                    hits += 1;
                    // Bounded ray just short of the hit misses it.
                    if t > 1e-9 {
                        let short = bvh.ray_cast(o, d, t * (1.0 - 1e-9));
                        assert!(short.is_none_or(|s| s.t < t), "t_max respected");
                    }
                }
                (None, None) => {}
                other => panic!("BVH and brute force disagree: {other:?}"),
            }
        }
        assert!(hits > 100, "{hits} hits: the test must exercise hits");
    }
}

/// The pairs of triangles that share no vertex and of which one has an edge
/// (from its lower vertex index) crossing the other, by testing all pairs.
fn brute_self_intersections(bvh: &TriangleBvh) -> Vec<[u32; 2]> {
    let (p, tris) = (bvh.positions(), bvh.triangles());
    let crosses = |s: [u32; 3], t: [u32; 3]| {
        (0..3).any(|e| {
            let (a, b) = (s[e].min(s[(e + 1) % 3]), s[e].max(s[(e + 1) % 3]));
            let [x, y, z] = t.map(|v| p[v as usize]);
            let dir = p[b as usize] - p[a as usize];
            dir != Vector3::zeros() && ray_triangle(p[a as usize], dir, 1.0, x, y, z).is_some()
        })
    };
    let mut out = Vec::new();
    for (i, &s) in tris.iter().enumerate() {
        for (j, &t) in tris.iter().enumerate().skip(i + 1) {
            if !s.iter().any(|v| t.contains(v)) && (crosses(s, t) || crosses(t, s)) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

#[test]
fn self_intersections_match_brute_force() {
    let mut rng = Rng(23);
    // Soups (no shared vertices), and a crumpled grid whose triangles share
    // vertices and edges and whose folds pass through each other.
    let mut cases: Vec<TriangleBvh> = [(40, 0.5), (400, 0.2), (1500, 0.08)]
        .iter()
        .map(|&(n, size)| random_soup(&mut rng, n, size))
        .collect();
    let mut crumpled = grid(24, 0.0);
    for q in &mut crumpled.positions {
        *q += 1.5 * (rng.point(1.0) - Point3::origin());
    }
    cases.push(TriangleBvh::from_mesh(&crumpled).unwrap());
    for bvh in &cases {
        let want = brute_self_intersections(bvh);
        assert!(
            want.len() >= 5,
            "{} pairs: the case must intersect",
            want.len()
        );
        assert_eq!(bvh.self_intersections(), want);
    }
}

/// Triangles of very unequal sizes (a few spanning the whole soup over
/// many small ones, so the grid's cells are made larger), and a mesh
/// crumpled so far that most of its triangles cross: the grid's pairs are
/// still the brute force's; bad input is refused.
#[test]
fn self_intersections_of_unequal_triangles_and_bad_input() {
    let mut rng = Rng(31);
    let soup = random_soup(&mut rng, 600, 0.05);
    let (mut positions, mut triangles) = (soup.positions().to_vec(), soup.triangles().to_vec());
    for _ in 0..40 {
        let base = positions.len() as u32;
        for _ in 0..3 {
            positions.push(rng.point(1.5));
        }
        triangles.push([base, base + 1, base + 2]);
    }
    let mut crumpled = grid(16, 0.0);
    for q in &mut crumpled.positions {
        *q += 6.0 * (rng.point(1.0) - Point3::origin());
    }
    // Two clusters of crossing triangles a million sizes apart along the
    // diagonal: the cells' keys would need far more than 32 bits.
    let far = random_soup(&mut rng, 200, 0.3);
    let mut p_far = far.positions().to_vec();
    for q in p_far.iter_mut().skip(300) {
        *q += Vector3::repeat(1e6);
    }
    let far = TriangleBvh::new(p_far, far.triangles().to_vec()).unwrap();
    for bvh in [
        TriangleBvh::new(positions, triangles).unwrap(),
        TriangleBvh::from_mesh(&crumpled).unwrap(),
        far,
    ] {
        let want = brute_self_intersections(&bvh);
        assert!(
            want.len() >= 10,
            "{} pairs: the case must intersect",
            want.len()
        );
        assert_eq!(
            self_intersecting_pairs(bvh.positions(), bvh.triangles()).unwrap(),
            want
        );
    }
    let p = [
        Point3::origin(),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let err = self_intersecting_pairs(&p, &[[0, 1, 3]]).unwrap_err();
    assert!(err.to_string().contains("refers to vertex 3"), "{err}");
    let nan = [p[0], p[1], Point3::new(Real::NAN, 0.0, 0.0)];
    assert!(self_intersecting_pairs(&nan, &[[0, 1, 2]]).is_err());
    assert!(
        self_intersecting_pairs(&p, &[[0, 1, 2]])
            .unwrap()
            .is_empty()
    );
}

#[test]
fn rays_through_shared_edges_and_vertices_hit_a_closed_mesh() {
    // Every ray from the cube's centre through an edge midpoint or a corner
    // must hit: no cracks between triangles.
    let bvh = TriangleBvh::from_mesh(&subdyn::examples::cube()).unwrap();
    let centre = Point3::new(0.5, 0.5, 0.5);
    let p = bvh.positions();
    for t in bvh.triangles() {
        let [a, b, c] = t.map(|v| p[v as usize]);
        for target in [
            a,
            Point3::from((a.coords + b.coords) * 0.5),
            Point3::from((c.coords + a.coords) * 0.5),
        ] {
            let hit = bvh
                .ray_cast(centre, target - centre, Real::INFINITY)
                .expect("hits");
            assert!((hit.t - 1.0).abs() < 1e-12, "t = {}", hit.t);
        }
    }
    // And from outside, axis-aligned rays along a face's diagonal edge.
    let hit = bvh
        .ray_cast(Point3::new(0.3, 0.3, -1.0), Vector3::z(), Real::INFINITY)
        .unwrap();
    assert_eq!(hit.t, 1.0);
}

// ---------------------------------------------------------------- stats

#[test]
fn stats_on_known_inputs() {
    let s = DistanceStats::new(&[3.0, 4.0]).unwrap();
    assert_eq!((s.count, s.min, s.max, s.mean), (2, 3.0, 4.0, 3.5));
    assert!((s.rms - (12.5f64).sqrt()).abs() < 1e-15);
    assert_eq!((s.median, s.p95), (3.0, 4.0));
    // 1..=100: nearest rank gives exactly the k-th value.
    let v: Vec<Real> = (1..=100).rev().map(Real::from).collect();
    let s = DistanceStats::new(&v).unwrap();
    assert_eq!((s.median, s.p95, s.max), (50.0, 95.0, 100.0));
    assert_eq!(percentile(&v, 0.0), Some(1.0));
    assert_eq!(percentile(&v, 0.5), Some(1.0));
    assert_eq!(percentile(&v, 1.0), Some(1.0));
    assert_eq!(percentile(&v, 1.5), Some(2.0));
    assert_eq!(percentile(&v, 99.9), Some(100.0));
    // 1..=21: P95 has rank ⌈19.95⌉ = 20.
    let v: Vec<Real> = (1..=21).map(Real::from).collect();
    assert_eq!(DistanceStats::new(&v).unwrap().p95, 20.0);
    assert_eq!(percentile(&[7.0], 95.0), Some(7.0));
    assert_eq!(percentile(&[], 50.0), None);
    assert_eq!(percentile(&[1.0], 101.0), None);
    assert!(DistanceStats::new(&[]).is_err());
    assert!(DistanceStats::new(&[1.0, Real::NAN]).is_err());
    assert!(DistanceStats::new(&[-1.0]).is_err());
    let pct = DistanceStats::new(&[1.0, 2.0]).unwrap().scaled(100.0 / 4.0);
    assert_eq!((pct.mean, pct.max, pct.count), (37.5, 50.0, 2));
}

#[test]
fn area_samples_follow_area_and_are_deterministic() {
    let mesh = grid(3, 0.0);
    let bvh = TriangleBvh::from_mesh(&mesh).unwrap();
    let a = area_samples(bvh.positions(), bvh.triangles(), 1800, 42).unwrap();
    let b = area_samples(bvh.positions(), bvh.triangles(), 1800, 42).unwrap();
    assert_eq!(a, b);
    // 18 equal triangles: 100 samples each.
    for t in 0..18 {
        assert_eq!(a.iter().filter(|s| s.1 == t).count(), 100);
    }
    // Every sample lies in its triangle.
    for (p, t) in &a {
        let [x, y, z] = bvh.triangles()[*t].map(|v| bvh.positions()[v as usize]);
        assert!(reference_distance(*p, x, y, z) < 1e-14);
    }
    let c = area_samples(bvh.positions(), bvh.triangles(), 1800, 43).unwrap();
    assert_ne!(a, c);
}

// ---------------------------------------------------------------- compare

#[test]
fn compare_a_mesh_with_itself_is_zero() {
    for mesh in [subdyn::examples::torus(10, 6, 1.0, 0.4), grid(4, 0.0)] {
        let s = Surface::mesh(&mesh).unwrap();
        let params = CompareParams {
            samples: 5000,
            seed: 3,
        };
        let c = compare(&s, &s, &params).unwrap();
        assert!(c.symmetric);
        // Zero up to rounding: a sample is a barycentric combination of its
        // triangle's corners, its projection another one (a few ulp apart).
        assert!(
            c.chamfer <= 1e-15 && c.hausdorff <= 1e-14,
            "{} {}",
            c.chamfer,
            c.hausdorff
        );
        assert!(c.chamfer_pct <= 1e-13 && c.hausdorff_pct <= 1e-13);
        assert!((c.normal_consistency.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(c.a_to_b.stats.count, 5000);
        assert_eq!(c.a_to_b.vertices, mesh.num_vertices());
    }
}

#[test]
fn compare_with_a_plane_moved_along_its_normal_is_the_offset() {
    let d = 0.125;
    let a = Surface::mesh(&grid(5, d)).unwrap();
    let b = Surface::mesh(&grid(5, 0.0)).unwrap();
    let c = compare(
        &a,
        &b,
        &CompareParams {
            samples: 4000,
            seed: 0,
        },
    )
    .unwrap();
    for side in [&c.a_to_b, c.b_to_a.as_ref().unwrap()] {
        for x in [
            side.stats.mean,
            side.stats.rms,
            side.stats.median,
            side.stats.p95,
            side.stats.min,
            side.max,
        ] {
            assert!((x - d).abs() <= 1e-12, "{x}");
        }
        assert!((side.normal_consistency.unwrap() - 1.0).abs() < 1e-12);
    }
    assert!((c.chamfer - d).abs() <= 1e-12 && (c.hausdorff - d).abs() <= 1e-12);
    let diag = (50.0 as Real).sqrt(); // B spans [0, 5]² × {0}
    assert!((c.diagonal - diag).abs() < 1e-12);
    assert!((c.chamfer_pct - 100.0 * d / diag).abs() <= 1e-10);
    assert!((c.hausdorff_pct - 100.0 * d / diag).abs() <= 1e-10);
    // Vertices only.
    let c0 = compare(
        &a,
        &b,
        &CompareParams {
            samples: 0,
            seed: 0,
        },
    )
    .unwrap();
    assert_eq!(c0.a_to_b.stats.count, 36);
    assert!((c0.chamfer - d).abs() <= 1e-12);
}

#[test]
fn compare_points_is_one_sided_and_uses_normals() {
    let b = Surface::mesh(&grid(2, 0.0)).unwrap();
    let pts = vec![
        Point3::new(0.5, 0.5, 0.1),
        Point3::new(1.5, 1.0, -0.3),
        Point3::new(3.0, 1.0, 0.0),
    ];
    let normals = vec![Vector3::z(), Vector3::new(1.0, 0.0, 1.0), Vector3::x()];
    let c = compare_points(&pts, Some(&normals), &b).unwrap();
    assert!(!c.symmetric && c.b_to_a.is_none());
    let mean = (0.1 + 0.3 + 1.0) / 3.0;
    assert!((c.chamfer - mean).abs() < 1e-15 && (c.hausdorff - 1.0).abs() < 1e-15);
    let nc = (1.0 + 0.5f64.sqrt() + 0.0) / 3.0;
    assert!((c.normal_consistency.unwrap() - nc).abs() < 1e-12);
    assert_eq!(c.a_to_b.distances.len(), 3);
    assert!(compare_points(&[], None, &b).is_err());
}

#[test]
fn limit_surface_samples_lie_on_the_limit_surface() {
    let cube = subdyn::examples::cube();
    let limit = Surface::limit(&cube, &RefineOptions::default(), 3).unwrap();
    assert!(limit.is_limit());
    let c = compare(
        &limit,
        &limit,
        &CompareParams {
            samples: 500,
            seed: 1,
        },
    )
    .unwrap();
    assert!(c.hausdorff < 1e-9, "{}", c.hausdorff);
    // The cage is farther from its limit surface than the limit from itself,
    // and a dense tessellation is close to it.
    let cage = Surface::mesh(&cube).unwrap();
    let far = compare(
        &cage,
        &limit,
        &CompareParams {
            samples: 500,
            seed: 1,
        },
    )
    .unwrap();
    assert!(far.hausdorff > 0.05);
    let refiner = subdyn::subdivision::Refiner::new(&cube, &RefineOptions::default()).unwrap();
    let (tess, _) = subdyn::limit::tessellate(&refiner, &cube.positions, 16).unwrap();
    let dense = compare(
        &Surface::mesh(&tess).unwrap(),
        &limit,
        &CompareParams {
            samples: 500,
            seed: 1,
        },
    )
    .unwrap();
    assert!(
        dense.hausdorff < 2e-3 && dense.hausdorff < far.hausdorff / 100.0,
        "dense {} far {}",
        dense.hausdorff,
        far.hausdorff
    );
}

// ---------------------------------------------------------------- CLI

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "expected success, got {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn write_obj(path: &Path, mesh: &PolyMesh) {
    subdyn::io::write_mesh(path, mesh, None).unwrap();
}

#[test]
fn cli_compare_writes_a_report_with_chamfer_and_hausdorff_pct() {
    let dir = tempfile::tempdir().unwrap();
    write_obj(&dir.path().join("a.obj"), &grid(3, 0.25));
    write_obj(&dir.path().join("b.obj"), &grid(3, 0.0));
    let out = ok(&run_subdyn(
        dir.path(),
        &[
            "compare",
            "a.obj",
            "b.obj",
            "--report",
            "r.json",
            "--samples",
            "3000",
            "--distances-out",
            "d.xyz",
        ],
    ));
    assert!(
        out.contains("Chamfer") && out.contains("Hausdorff"),
        "{out}"
    );
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    let diag = (18.0 as Real).sqrt();
    for key in ["chamfer_pct", "hausdorff_pct"] {
        let v = r[key].as_f64().unwrap_or_else(|| panic!("{key} in {r}"));
        assert!((v - 100.0 * 0.25 / diag).abs() < 1e-9, "{key} = {v}");
    }
    assert!((r["chamfer"].as_f64().unwrap() - 0.25).abs() < 1e-12);
    assert_eq!(r["symmetric"], true);
    assert_eq!(r["a_to_b"]["stats"]["count"], 3000);
    assert!(
        r["definitions"]["chamfer"]
            .as_str()
            .unwrap()
            .contains("mean")
    );
    assert!(r["timings_s"]["total"].as_f64().unwrap() >= 0.0);
    let lines = std::fs::read_to_string(dir.path().join("d.xyz")).unwrap();
    assert_eq!(lines.lines().count(), 3000);
    let last: Vec<Real> = lines
        .lines()
        .last()
        .unwrap()
        .split(' ')
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(last.len(), 4);
    assert!((last[3] - 0.25).abs() < 1e-12 && (last[2] - 0.25).abs() < 1e-12);
}

#[test]
fn cli_compare_point_file_is_one_sided() {
    let dir = tempfile::tempdir().unwrap();
    write_obj(&dir.path().join("b.obj"), &grid(2, 0.0));
    std::fs::write(dir.path().join("p.xyz"), "0.5 0.5 0.5\n1 1 -0.25\n").unwrap();
    let out = ok(&run_subdyn(
        dir.path(),
        &["compare", "p.xyz", "b.obj", "--report", "r.json", "-q"],
    ));
    assert!(out.contains("one-sided"), "{out}");
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(r["symmetric"], false);
    assert_eq!(r["b_to_a"], Value::Null);
    assert_eq!(r["a"]["kind"], "points");
    assert!((r["hausdorff"].as_f64().unwrap() - 0.5).abs() < 1e-15);
    assert!((r["chamfer"].as_f64().unwrap() - 0.375).abs() < 1e-15);
    assert!(r["hausdorff_pct"].as_f64().is_some() && r["chamfer_pct"].as_f64().is_some());
}

#[test]
fn cli_compare_bad_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    write_obj(&dir.path().join("a.obj"), &grid(2, 0.0));
    std::fs::write(dir.path().join("p.xyz"), "0 0 0\n1 0 0\n0 1 0\n").unwrap();
    let inputs = ["a.obj", "p.xyz"];
    // B without faces.
    let out = run_subdyn(
        dir.path(),
        &["compare", "a.obj", "p.xyz", "--report", "r.json"],
    );
    assert_clean_failure(dir.path(), &out, &["no faces"], &inputs);
    // A missing file.
    let out = run_subdyn(
        dir.path(),
        &["compare", "missing.obj", "a.obj", "--report", "r.json"],
    );
    assert_clean_failure(dir.path(), &out, &["missing.obj"], &inputs);
    let out = run_subdyn(
        dir.path(),
        &["compare", "a.obj", "missing.obj", "--report", "r.json"],
    );
    assert_clean_failure(dir.path(), &out, &["missing.obj"], &inputs);
    // --limit-a on a point file.
    let out = run_subdyn(
        dir.path(),
        &[
            "compare",
            "p.xyz",
            "a.obj",
            "--limit-a",
            "--report",
            "r.json",
        ],
    );
    assert_clean_failure(dir.path(), &out, &["--limit-a"], &inputs);
    // A NaN coordinate in A.
    std::fs::write(dir.path().join("nan.xyz"), "0 0 0\n1 nan 0\n").unwrap();
    let out = run_subdyn(
        dir.path(),
        &["compare", "nan.xyz", "a.obj", "--report", "r.json"],
    );
    assert_clean_failure(
        dir.path(),
        &out,
        &["nan.xyz"],
        &["a.obj", "p.xyz", "nan.xyz"],
    );
}

#[test]
fn cli_bench_distance_prints_json_last_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&run_subdyn(
        dir.path(),
        &[
            "bench",
            "distance",
            "--points",
            "2000",
            "--triangles",
            "2000",
            "-q",
        ],
    ));
    let last = out.lines().last().unwrap();
    let v: Value = serde_json::from_str(last).unwrap();
    for key in [
        "build_s",
        "query_s",
        "points",
        "triangles",
        "threads",
        "speedup_vs_brute",
    ] {
        assert!(v.get(key).is_some(), "{key} in {last}");
    }
    assert_eq!(v["points"], 2000);
    let t = v["triangles"].as_u64().unwrap();
    assert!((1800..=2200).contains(&t), "{t} triangles");
    assert_eq!(v["max_abs_diff_vs_brute"].as_f64().unwrap(), 0.0);
}

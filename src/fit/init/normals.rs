//! Oriented normals of a point cloud and the signed distance they define.
//!
//! Hoppe, DeRose, Duchamp, McDonald and Stuetzle, *Surface reconstruction
//! from unorganized points* (SIGGRAPH 1992):
//!
//! - §3.2: each point's tangent plane is the least-squares plane of its `k`
//!   nearest neighbours, its normal the eigenvector of the smallest
//!   eigenvalue of their covariance;
//! - §3.3: the normals are oriented consistently by propagation along a
//!   minimum spanning tree of the `k`-nearest-neighbour graph with edge cost
//!   `1 − |nᵢ · nⱼ|` (nearly parallel planes first), each newly reached
//!   normal flipped to agree with its tree parent. Each connected component
//!   of the graph starts from its point farthest from the cloud's centroid,
//!   whose normal is turned away from the centroid: at the farthest point
//!   the surface touches the sphere about the centroid through it, so its
//!   outward normal is radial;
//! - §3.4: the signed distance of `x` is its offset `(x − o) · n` from the
//!   tangent plane of the nearest point. We average the offsets from the
//!   planes of the [`PLANES`] nearest points, which halves the effect of
//!   range noise on the sign near the surface.
//!
//! The scan's own normals, when the file has them, are not used: the
//! comparisons against Open3D and pymeshlab give every method points only.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::math::{Point3, Real, Vector3};

/// Neighbours of a point's tangent plane and of the propagation graph.
const NEIGHBOURS: usize = 12;

/// Tangent planes averaged by [`SignedDistance::at`].
pub const PLANES: usize = 4;

/// Unit normals of `points` from their `NEIGHBOURS` nearest neighbours,
/// oriented by minimum-spanning-tree propagation (module docs).
pub fn oriented_normals(points: &[Point3], tree: &ImmutableKdTree<Real, 3>) -> Vec<Vector3> {
    let k = NonZero::new((NEIGHBOURS + 1).min(points.len())).unwrap_or(NonZero::<usize>::MIN);
    let neighbours: Vec<Vec<u32>> = points
        .par_iter()
        .map(|p| {
            tree.nearest_n::<SquaredEuclidean>(&[p.x, p.y, p.z], k)
                .iter()
                .map(|nn| nn.item as u32)
                .collect()
        })
        .collect();
    let mut normals: Vec<Vector3> = neighbours
        .par_iter()
        .map(|nb| plane_normal(points, nb))
        .collect();
    let graph = symmetric_graph(&neighbours);
    let mut reached = vec![false; points.len()];
    // The cheapest known edge into each point not yet reached and its other
    // end: an edge no cheaper (or, at equal cost, from a lower parent, which
    // the heap would pop later) is not pushed, as it could only be popped
    // after the point is reached.
    let mut best: Vec<(Real, u32)> = vec![(Real::INFINITY, 0); points.len()];
    let centroid =
        points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len().max(1) as Real;
    let away = |i: usize| points[i].coords - centroid;
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| away(b).norm_squared().total_cmp(&away(a).norm_squared()));
    let mut heap = BinaryHeap::new();
    for seed in order {
        if reached[seed] {
            continue;
        }
        if normals[seed].dot(&away(seed)) < 0.0 {
            normals[seed] = -normals[seed];
        }
        heap.push((Reverse(Cost(0.0)), seed as u32, seed as u32));
        while let Some((_, i, parent)) = heap.pop() {
            let i = i as usize;
            if reached[i] {
                continue;
            }
            reached[i] = true;
            if normals[i].dot(&normals[parent as usize]) < 0.0 {
                normals[i] = -normals[i];
            }
            for &j in graph.neighbours(i) {
                let j = j as usize;
                if reached[j] {
                    continue;
                }
                let cost = 1.0 - normals[i].dot(&normals[j]).abs();
                let (known, from) = best[j];
                if cost > known || (cost == known && (i as u32) < from) {
                    continue;
                }
                best[j] = (cost, i as u32);
                heap.push((Reverse(Cost(cost)), j as u32, i as u32));
            }
        }
    }
    normals
}

/// Unit normal of the least-squares plane through `points[nb]` (zero for
/// fewer than three points or a degenerate neighbourhood).
fn plane_normal(points: &[Point3], nb: &[u32]) -> Vector3 {
    if nb.len() < 3 {
        return Vector3::zeros();
    }
    let centre = nb
        .iter()
        .fold(Vector3::zeros(), |s, &j| s + points[j as usize].coords)
        / nb.len() as Real;
    let mut cov = nalgebra::Matrix3::<Real>::zeros();
    for &j in nb {
        let d = points[j as usize].coords - centre;
        cov += d * d.transpose();
    }
    let eig = cov.symmetric_eigen();
    let (smallest, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .unwrap_or((0, &0.0));
    let n = eig.eigenvectors.column(smallest).into_owned();
    n.try_normalize(0.0).unwrap_or_else(Vector3::zeros)
}

/// A graph in compressed rows: the neighbours of `i` are
/// `targets[offsets[i]..offsets[i + 1]]`.
struct Graph {
    offsets: Vec<usize>,
    targets: Vec<u32>,
}

impl Graph {
    fn neighbours(&self, i: usize) -> &[u32] {
        &self.targets[self.offsets[i]..self.offsets[i + 1]]
    }
}

/// The symmetric `k`-nearest-neighbour graph: `j` next to `i` when either
/// is among the other's nearest (`neighbours[i]` first, in its order, then
/// the points that have `i` among theirs and are not among `i`'s).
fn symmetric_graph(neighbours: &[Vec<u32>]) -> Graph {
    let n = neighbours.len();
    // The extra (reverse) edges, grouped by their source in order of `i`.
    let mut extra: Vec<(u32, u32)> = Vec::new();
    for (i, nb) in neighbours.iter().enumerate() {
        for &j in nb {
            if j as usize != i && !neighbours[j as usize].contains(&(i as u32)) {
                extra.push((j, i as u32));
            }
        }
    }
    extra.sort_by_key(|e| e.0);
    let mut offsets = Vec::with_capacity(n + 1);
    offsets.push(0);
    let mut targets =
        Vec::with_capacity(neighbours.iter().map(Vec::len).sum::<usize>() + extra.len());
    let mut rest = extra.iter().peekable();
    for (i, nb) in neighbours.iter().enumerate() {
        targets.extend_from_slice(nb);
        while let Some(&(_, j)) = rest.next_if(|e| e.0 as usize == i) {
            targets.push(j);
        }
        offsets.push(targets.len());
    }
    Graph { offsets, targets }
}

/// A total order on costs for the propagation heap (costs are finite).
#[derive(Clone, Copy, PartialEq)]
struct Cost(Real);

impl Eq for Cost {}

impl PartialOrd for Cost {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Cost {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Hoppe et al.'s signed distance of the oriented tangent planes (module
/// docs): negative inside, positive outside.
pub struct SignedDistance<'a> {
    points: &'a [Point3],
    normals: &'a [Vector3],
    tree: &'a ImmutableKdTree<Real, 3>,
}

impl<'a> SignedDistance<'a> {
    /// The signed distance of `points` with oriented `normals`.
    pub fn new(
        points: &'a [Point3],
        normals: &'a [Vector3],
        tree: &'a ImmutableKdTree<Real, 3>,
    ) -> SignedDistance<'a> {
        SignedDistance {
            points,
            normals,
            tree,
        }
    }

    /// Mean offset of `x` from the tangent planes of its [`PLANES`] nearest
    /// points, and the distance to the nearest point.
    pub fn at(&self, x: &Point3) -> (Real, Real) {
        let Some(k) = NonZero::new(PLANES.min(self.points.len())) else {
            return (Real::INFINITY, Real::INFINITY);
        };
        let nn = self.tree.nearest_n::<SquaredEuclidean>(&[x.x, x.y, x.z], k);
        let offset = nn
            .iter()
            .map(|n| {
                let j = n.item as usize;
                (x - self.points[j]).dot(&self.normals[j])
            })
            .sum::<Real>()
            / nn.len() as Real;
        (
            offset,
            nn.first().map_or(Real::INFINITY, |n| n.distance.sqrt()),
        )
    }

    /// The points and their oriented normals.
    pub fn oriented_points(&self) -> impl Iterator<Item = (&'a Point3, &'a Vector3)> + 'a {
        self.points.iter().zip(self.normals)
    }

    /// Whether `x` lies between two sheets of surface facing each other
    /// within `radius`: among the points whose tangent planes have `x` on
    /// their outer side, two normals at more than 120° from each other. The
    /// pair is searched in two sweeps (the normal farthest from the first
    /// one, then the normal farthest from that), which finds it whenever the
    /// facing normals form two opposed clusters.
    pub fn between_sheets(&self, x: &Point3, radius: Real) -> bool {
        let facing: Vec<Vector3> = self
            .tree
            .within_unsorted::<SquaredEuclidean>(&[x.x, x.y, x.z], radius * radius)
            .iter()
            .map(|n| n.item as usize)
            .filter(|&j| (x - self.points[j]).dot(&self.normals[j]) > 0.0)
            .map(|j| self.normals[j])
            .collect();
        let Some(&first) = facing.first() else {
            return false;
        };
        let farthest = |a: Vector3| {
            facing
                .iter()
                .copied()
                .min_by(|p, q| p.dot(&a).total_cmp(&q.dot(&a)))
                .unwrap_or(a)
        };
        let second = farthest(first);
        let third = farthest(second);
        first.dot(&second).min(second.dot(&third)) < -0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::init::sampling::point_tree;

    /// Points on a sphere of radius 1 (Fibonacci lattice).
    fn sphere(n: usize) -> Vec<Point3> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as Real + 0.5) / n as Real;
                let r = (1.0 - y * y).sqrt();
                let t = golden * i as Real;
                Point3::new(r * t.cos(), y, r * t.sin())
            })
            .collect()
    }

    #[test]
    fn sphere_normals_point_outwards_and_sign_inside_negative() {
        let pts = sphere(3000);
        let tree = point_tree(&pts);
        let normals = oriented_normals(&pts, &tree);
        let worst = pts
            .iter()
            .zip(&normals)
            .map(|(p, n)| p.coords.dot(n))
            .fold(Real::INFINITY, Real::min);
        assert!(
            worst > 0.99,
            "an estimated normal is off the radial direction: {worst}"
        );
        let sd = SignedDistance::new(&pts, &normals, &tree);
        for (x, want) in [(0.5, -0.5), (0.9, -0.1), (1.2, 0.2)] {
            let (got, _) = sd.at(&Point3::new(x, 0.0, 0.0));
            assert!(
                (got - want).abs() < 0.02,
                "signed distance at {x}: {got}, want {want}"
            );
        }
    }

    #[test]
    fn two_close_parallel_sheets_get_opposite_normals() {
        // A thin slab's top and bottom faces, 0.2 apart, sampled at 0.05:
        // the tree must not cross between them, so the outward normals differ.
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let (x, y) = (i as Real * 0.05, j as Real * 0.05);
                pts.push(Point3::new(x, y, 0.1));
                pts.push(Point3::new(x, y, -0.1));
            }
        }
        let tree = point_tree(&pts);
        let normals = oriented_normals(&pts, &tree);
        let agree = pts
            .iter()
            .zip(&normals)
            .filter(|(p, n)| p.z.signum() == n.z.signum() && n.z.abs() > 0.99)
            .count();
        assert_eq!(
            agree,
            pts.len(),
            "every normal points away from the slab's middle"
        );
    }
}

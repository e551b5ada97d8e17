//! The width of the narrow gaps of a closed scan: free space between two
//! sheets of surface facing each other (a quadruped's legs, fingers).
//!
//! An occupancy cage can only keep a gap open when its voxels are smaller
//! than the gap ([`super::carve`] needs 1.5 voxels), so the occupancy's
//! voxel is chosen from this estimate. From up to [`SAMPLES`] evenly
//! strided points `p` with oriented normal `n` ([`super::normals`]), march
//! `x = p + t n` outwards in steps of `step` up to `reach`; the gap at `p`
//! is the first `t` whose nearest point `q` lies within `hit` of `x` (at
//! least a step; the occupancy passes the sampling radius, so that holes
//! between scan points are not mistaken for free space) and faces back
//! (`n_q · n < −0.7`). Creases do not count: at a concave corner the two
//! sheets meet at an angle, far from opposed. The estimate is the median
//! of the gaps found (it runs up to `hit` short of the true width), `None`
//! when fewer than [`MIN_HITS`] points see a facing sheet: the sheets
//! facing across a narrow gap are often seen at grazing angles and thinly
//! sampled (28 of 4,773 samples on the 8-view Spot scan).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::math::{Point3, Real, Vector3};

/// Points marched from, at most.
pub const SAMPLES: usize = 5000;

/// Points that must meet a facing sheet for a gap to be reported.
pub const MIN_HITS: usize = 10;

/// Narrow-gap width of `points` (module docs), looking no farther than
/// `reach`, in steps of `step`, a sheet counting as hit within `hit`.
pub fn narrow_gap(
    points: &[Point3],
    normals: &[Vector3],
    tree: &ImmutableKdTree<Real, 3>,
    step: Real,
    hit: Real,
    reach: Real,
) -> Option<Real> {
    let hit = hit.max(step);
    if points.is_empty() || step.is_nan() || step <= 0.0 {
        return None;
    }
    let stride = points.len().div_ceil(SAMPLES).max(1);
    let steps = (reach / step).ceil() as usize;
    let mut gaps: Vec<Real> = points
        .par_iter()
        .zip(normals)
        .step_by(stride)
        .filter_map(|(p, n)| {
            // Step `i` is tried unless a nearest distance `d` seen at step
            // `j` rules it out: every point is at least `d − (i − j) step`
            // from step `i`, so it cannot be within `hit` while that is
            // larger (the same answer as trying every step, in fewer
            // queries where the march crosses free space).
            let mut i = 1;
            while i <= steps {
                let t = i as Real * step;
                let x = p + n * t;
                let nn = tree.nearest_one::<SquaredEuclidean>(&[x.x, x.y, x.z]);
                if nn.distance <= hit * hit && normals[nn.item as usize].dot(n) < -0.7 {
                    return Some(t);
                }
                // The first step that may be within `hit`: `(i' − i) step ≥
                // d − hit` (less a hair, for round-off).
                let skip = (nn.distance.sqrt() - hit) / step - 1e-9;
                i += (skip.ceil() as usize).max(1);
            }
            None
        })
        .collect();
    if gaps.len() < MIN_HITS {
        return None;
    }
    let k = gaps.len() / 2;
    gaps.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    Some(gaps[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::init::normals::oriented_normals;
    use crate::fit::init::sampling::point_tree;

    /// Two square slabs (each 1 × 1 × 0.4, sampled on their six faces at
    /// 0.025) side by side along x with a gap `g` between them.
    fn two_slabs(g: Real) -> Vec<Point3> {
        let mut pts = Vec::new();
        let n = 40;
        for x0 in [0.0, 0.4 + g] {
            for i in 0..=n {
                for j in 0..=n {
                    let (a, b) = (i as Real / n as Real, j as Real / n as Real);
                    for p in [
                        Point3::new(x0, a, b),
                        Point3::new(x0 + 0.4, a, b),
                        Point3::new(x0 + 0.4 * a, 0.0, b),
                        Point3::new(x0 + 0.4 * a, 1.0, b),
                        Point3::new(x0 + 0.4 * a, b, 0.0),
                        Point3::new(x0 + 0.4 * a, b, 1.0),
                    ] {
                        pts.push(p);
                    }
                }
            }
        }
        pts
    }

    #[test]
    fn gap_between_two_slabs_is_measured_and_a_single_slab_has_none() {
        for g in [0.1, 0.2] {
            let pts = two_slabs(g);
            let tree = point_tree(&pts);
            let normals = oriented_normals(&pts, &tree);
            let got = narrow_gap(&pts, &normals, &tree, 0.01, 0.01, 0.5);
            let got = got.unwrap_or(Real::NAN);
            assert!((got - g).abs() <= 0.011, "gap {g}: measured {got}");
        }
        let one: Vec<Point3> = two_slabs(0.1)
            .into_iter()
            .filter(|p| p.x <= 0.4 + 1e-12)
            .collect();
        let tree = point_tree(&one);
        let normals = oriented_normals(&one, &tree);
        assert_eq!(narrow_gap(&one, &normals, &tree, 0.01, 0.01, 0.5), None);
    }
}

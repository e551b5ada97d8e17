//! The two-sided forces of the volume recovery (`RecoverParams::
//! two_sided_weight`): iso-surface points that no part of the model's
//! surface comes near pull their closest points, as the scan fit's
//! surface-to-data springs do, so that a part the surface missed grows
//! back at any level.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::error::Result;
use crate::limit::{ClosestPoint, ClosestPointEngine};
use crate::math::{Point3, Real};

/// The two-sided forces' candidates: iso-surface points, and each one's
/// nearest sample carried from one step to the next of a level (the same
/// samples, moved; `u32::MAX` before the first search).
pub(super) struct Candidates {
    pub points: Vec<Point3>,
    nearest: Vec<u32>,
}

impl Candidates {
    pub fn new(points: Vec<Point3>) -> Candidates {
        let nearest = vec![u32::MAX; points.len()];
        Candidates { points, nearest }
    }
}

/// The points of `from` outside the limit surface of `engine` (whose
/// samples `xs`, with tangents `us`, `vs`, sit at `at`) and farther than
/// `reach` from it, with their closest points: the two-sided forces'
/// springs. A point within `reach` of a sample, or behind its nearest
/// sample's tangent plane, is left out at once; the others are searched
/// from their nearest sample's patch. Points inside are left out: there the surface bridges a
/// groove that the image springs along its normals see (a sulcus, a gap
/// between legs), and a coarse level cannot follow a deep one; outside, it
/// has missed a part (a horn tip, a leg the cage lost).
///
/// A point still within `reach` of its last nearest sample has its nearest
/// sample within reach too, so is left out without a search. The result is
/// the same as searching every point; most points stay near the surface
/// between steps, so most searches are saved.
pub(super) fn far_points(
    engine: &ClosestPointEngine,
    xs: &[Point3],
    us: &[Point3],
    vs: &[Point3],
    at: &[(usize, [Real; 2])],
    from: &mut Candidates,
    reach: Real,
) -> Result<(Vec<Point3>, Vec<ClosestPoint>)> {
    if from.points.is_empty() || xs.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let reach2 = reach * reach;
    let near = |b: &Point3, i: u32| {
        xs.get(i as usize)
            .is_some_and(|x| (b - x).norm_squared() <= reach2)
    };
    if from
        .points
        .par_iter()
        .zip(from.nearest.par_iter())
        .all(|(b, &i)| near(b, i))
    {
        return Ok((Vec::new(), Vec::new()));
    }
    let tree = ImmutableKdTree::<Real, 3>::new_from_slice(
        &xs.iter().map(|x| [x.x, x.y, x.z]).collect::<Vec<_>>(),
    );
    let (candidates, starts): (Vec<Point3>, Vec<(u32, [Real; 2])>) = from
        .points
        .par_iter()
        .zip(from.nearest.par_iter_mut())
        .filter_map(|(b, cached)| {
            if near(b, *cached) {
                return None;
            }
            let nn = tree.nearest_one::<SquaredEuclidean>(&[b.x, b.y, b.z]);
            *cached = nn.item as u32;
            let i = nn.item as usize;
            let outward = (b - xs[i]).dot(&us[i].coords.cross(&vs[i].coords)) > 0.0;
            (nn.distance > reach2 && outward).then(|| {
                let (f, st) = at[i];
                (*b, (f as u32, st))
            })
        })
        .unzip();
    let closest = engine.closest_points_near(&candidates, &starts)?;
    Ok(candidates
        .into_iter()
        .zip(closest)
        .filter(|(b, c)| c.distance > reach && (b - c.point).dot(&c.normal) > 0.0)
        .unzip())
}

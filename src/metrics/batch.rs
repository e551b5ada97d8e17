//! `distances`: closest points of many queries on a [`TriangleBvh`], in
//! parallel and in Morton (Z-curve) order, so that consecutive queries of a
//! thread walk the same nodes while they are still in cache.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, bounding_box};

use super::bvh::{Nearest, TriangleBvh};

/// Below this many queries the Morton sort is not worth its cost.
const SORT_FROM: usize = 4096;
/// Queries per parallel task; within a task each query starts from the
/// previous one's answer.
const CHUNK: usize = 256;

/// The closest point on `bvh` of every query, in the queries' order,
/// computed in parallel with rayon. Errors (naming the first one) when a
/// query has a non-finite coordinate.
///
/// Large batches are processed in the order of the queries' 63-bit Morton
/// codes (21 bits per axis over the queries' bounding box; Morton, IBM
/// technical report 1966), which halves the time of random point sets on
/// meshes larger than the cache; results are returned in input order.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::{TriangleBvh, distances};
/// let bvh = TriangleBvh::from_mesh(&subdyn::examples::cube())?;
/// let found = distances(&bvh, &[Point3::new(0.5, 0.5, 0.5), Point3::new(3.0, 0.5, 0.5)])?;
/// assert_eq!(found[0].distance, 0.5);
/// assert_eq!(found[1].distance, 2.0);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn distances(bvh: &TriangleBvh, queries: &[Point3]) -> Result<Vec<Nearest>> {
    if let Some(i) = queries
        .par_iter()
        .position_first(|q| !q.coords.iter().all(|c| c.is_finite()))
    {
        let q = queries[i];
        return Err(Error::non_finite(format!(
            "query point {i} has a non-finite coordinate ({}, {}, {})",
            q.x, q.y, q.z
        )));
    }
    let nearest = |q: &Point3| {
        bvh.closest_point(*q)
            .ok_or_else(|| Error::non_finite("query point is not finite"))
    };
    if queries.len() < SORT_FROM || queries.len() > u32::MAX as usize {
        return queries.par_iter().map(nearest).collect();
    }
    let order = morton_order(queries);
    // Gather the queries in Morton order first: the scattered reads then
    // overlap, instead of stalling each traversal.
    let gathered: Vec<Point3> = order.par_iter().map(|&i| queries[i as usize]).collect();
    let sorted: Vec<Nearest> = gathered
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut hint = None;
            chunk.iter().map(move |q| {
                let (found, slot) = bvh
                    .closest_point_from(*q, hint)
                    .ok_or_else(|| Error::non_finite("query point is not finite"))?;
                hint = Some(slot);
                Ok(found)
            })
        })
        .collect::<Result<_>>()?;
    // Position of each query in `sorted`, then a parallel gather.
    let mut rank = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        rank[i as usize] = k as u32;
    }
    Ok(rank.par_iter().map(|&k| sorted[k as usize]).collect())
}

/// Indices of `points` sorted by Morton code over their bounding box.
fn morton_order(points: &[Point3]) -> Vec<u32> {
    let (lo, hi) = bounding_box(points).unwrap_or((Point3::origin(), Point3::origin()));
    const CELLS: Real = ((1u64 << 21) - 1) as Real;
    let scale = (hi - lo).map(|e| if e > 0.0 { CELLS / e } else { 0.0 });
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let cell = |k: usize| (((p[k] - lo[k]) * scale[k]) as u64).min(CELLS as u64);
            (
                spread(cell(0)) | spread(cell(1)) << 1 | spread(cell(2)) << 2,
                i as u32,
            )
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(mut x: u64) -> u64 {
    x &= 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

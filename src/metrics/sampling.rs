//! Area-weighted sample points on a triangle mesh, deterministic for a seed.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real};

/// `n` points on the triangles, distributed by area: triangle `t` receives
/// `⌊n A_t / A⌋` or `⌈n A_t / A⌉` samples (systematic sampling: one random
/// offset `r`, thresholds `(i + r) A / n` on the cumulative areas), and each
/// lands uniformly inside its triangle by Osada et al., "Shape
/// distributions", *ACM TOG* 21(4), 2002, eq. 1:
/// `p = (1 − √r₁) a + √r₁ (1 − r₂) b + √r₁ r₂ c`.
///
/// Returns `(point, triangle)` pairs, in triangle order. The same `seed`
/// gives the same points on every machine and thread count. Zero-area
/// triangles get no samples; errors when every triangle has zero area (and
/// `n > 0`) or an index is out of range.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::area_samples;
/// let p = |x, y| Point3::new(x, y, 0.0);
/// // A unit square as two triangles of area 1/2 each.
/// let pos = vec![p(0., 0.), p(1., 0.), p(1., 1.), p(0., 1.)];
/// let s = area_samples(&pos, &[[0, 1, 2], [0, 2, 3]], 1000, 7)?;
/// assert_eq!(s.len(), 1000);
/// assert_eq!(s.iter().filter(|(_, t)| *t == 0).count(), 500); // equal areas
/// assert!(s.iter().all(|(q, _)| (0.0..=1.0).contains(&q.x) && (0.0..=1.0).contains(&q.y)));
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn area_samples(
    positions: &[Point3],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> Result<Vec<(Point3, usize)>> {
    if n == 0 {
        return Ok(Vec::new());
    }
    let np = positions.len();
    if let Some(t) = triangles
        .iter()
        .position(|tri| tri.iter().any(|&v| v as usize >= np))
    {
        return Err(Error::input(format!(
            "triangle {t} refers to a vertex beyond the {np} positions"
        )));
    }
    let corners = |t: usize| triangles[t].map(|v| positions[v as usize]);
    let areas: Vec<Real> = (0..triangles.len())
        .into_par_iter()
        .map(|t| {
            let [a, b, c] = corners(t);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .collect();
    let total: Real = areas.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::input(format!(
            "cannot sample {n} points: the {} triangles have total area {total}",
            triangles.len()
        )));
    }
    // Systematic assignment of sample i to the triangle whose cumulative
    // area interval holds (i + r) A / n.
    let offset = unit(hash(seed, u64::MAX, 0));
    let mut owner = Vec::with_capacity(n);
    let mut acc = 0.0;
    let mut t = 0;
    for i in 0..n {
        let target = (i as Real + offset) * total / n as Real;
        while t + 1 < areas.len() && (acc + areas[t] <= target || areas[t] == 0.0) {
            acc += areas[t];
            t += 1;
        }
        owner.push(t);
    }
    Ok(owner
        .par_iter()
        .enumerate()
        .map(|(i, &t)| {
            let [a, b, c] = corners(t);
            let s = unit(hash(seed, i as u64, 1)).sqrt();
            let r2 = unit(hash(seed, i as u64, 2));
            let p = a.coords * (1.0 - s) + b.coords * (s * (1.0 - r2)) + c.coords * (s * r2);
            (Point3::from(p), t)
        })
        .collect())
}

/// A 64-bit hash of `(seed, index, stream)` (SplitMix64 finaliser).
fn hash(seed: u64, index: u64, stream: u64) -> u64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(index.wrapping_mul(0xD1B5_4A32_D192_ED03))
        .wrapping_add(stream.wrapping_mul(0x8CB9_2BA7_2F3D_8DD7));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A hash mapped to `[0, 1)` with 53 random bits.
fn unit(h: u64) -> Real {
    (h >> 11) as Real / (1u64 << 53) as Real
}

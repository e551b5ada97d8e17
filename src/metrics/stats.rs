//! `DistanceStats`: summary statistics of a set of distances.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::math::Real;

/// Count, minimum, mean, root mean square, median, 95th percentile and
/// maximum of a set of distances `d_1 … d_n`:
///
/// - `mean = Σ d_i / n`, `rms = √(Σ d_i² / n)`;
/// - percentiles by the nearest-rank rule ([`percentile`]): `median` is
///   `P_50`, `p95` is `P_95`, the smallest value with at least 95 % of the
///   values at or below it — always one of the inputs, never interpolated.
///
/// ```
/// use subdyn::metrics::DistanceStats;
/// let d: Vec<f64> = (1..=20).map(f64::from).collect(); // 1, 2, …, 20
/// let s = DistanceStats::new(&d)?;
/// assert_eq!((s.count, s.min, s.max), (20, 1.0, 20.0));
/// assert_eq!(s.mean, 10.5);
/// assert_eq!(s.median, 10.0); // rank ⌈0.50 · 20⌉ = 10
/// assert_eq!(s.p95, 19.0);    // rank ⌈0.95 · 20⌉ = 19
/// # Ok::<(), subdyn::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DistanceStats {
    /// Number of distances.
    pub count: usize,
    /// Smallest distance.
    pub min: Real,
    /// Arithmetic mean.
    pub mean: Real,
    /// Root mean square.
    pub rms: Real,
    /// 50th percentile (nearest rank).
    pub median: Real,
    /// 95th percentile (nearest rank).
    pub p95: Real,
    /// Largest distance.
    pub max: Real,
}

impl DistanceStats {
    /// Statistics of `distances`; errors when there are none or one is
    /// negative or not finite (naming the first).
    pub fn new(distances: &[Real]) -> Result<Self> {
        if distances.is_empty() {
            return Err(Error::input("no distances to summarise"));
        }
        if let Some(i) = distances.iter().position(|d| !(d.is_finite() && *d >= 0.0)) {
            return Err(Error::input(format!(
                "distance {i} is {}: distances must be finite and non-negative",
                distances[i]
            )));
        }
        let n = distances.len() as Real;
        let (sum, sum2) = distances
            .iter()
            .fold((0.0, 0.0), |(s, s2), &d| (s + d, s2 + d * d));
        let mut work = distances.to_vec();
        Ok(DistanceStats {
            count: distances.len(),
            min: distances.iter().copied().fold(Real::INFINITY, Real::min),
            mean: sum / n,
            rms: (sum2 / n).sqrt(),
            median: select_rank(&mut work, 50.0),
            p95: select_rank(&mut work, 95.0),
            max: distances.iter().copied().fold(0.0, Real::max),
        })
    }

    /// Every figure multiplied by `factor` (for instance `100 / diagonal`
    /// for percent of a bounding-box diagonal); `count` is kept.
    pub fn scaled(&self, factor: Real) -> DistanceStats {
        DistanceStats {
            count: self.count,
            min: self.min * factor,
            mean: self.mean * factor,
            rms: self.rms * factor,
            median: self.median * factor,
            p95: self.p95 * factor,
            max: self.max * factor,
        }
    }
}

/// The `p`-th percentile (`0 ≤ p ≤ 100`) of `values` by the nearest-rank
/// rule: with the values sorted increasingly as `x_(1) ≤ … ≤ x_(n)`, `P_p =
/// x_(r)` with rank `r = max(1, ⌈p n / 100⌉)`. So `P_0` is the minimum,
/// `P_100` the maximum, and `P_p` is the smallest value with at least `p` %
/// of the values at or below it. Found by selection, `O(n)`, not by sorting.
/// `None` for no values, `p` outside `[0, 100]` or a NaN value.
///
/// ```
/// use subdyn::metrics::percentile;
/// let v = [15.0, 20.0, 35.0, 40.0, 50.0];
/// assert_eq!(percentile(&v, 30.0), Some(20.0)); // r = ⌈1.5⌉ = 2
/// assert_eq!(percentile(&v, 40.0), Some(20.0)); // r = 2
/// assert_eq!(percentile(&v, 50.0), Some(35.0)); // r = ⌈2.5⌉ = 3
/// assert_eq!(percentile(&v, 100.0), Some(50.0));
/// ```
pub fn percentile(values: &[Real], p: Real) -> Option<Real> {
    if values.is_empty() || !(0.0..=100.0).contains(&p) || values.iter().any(|v| v.is_nan()) {
        return None;
    }
    Some(select_rank(&mut values.to_vec(), p))
}

/// Nearest-rank percentile by `select_nth_unstable` (reorders `work`).
fn select_rank(work: &mut [Real], p: Real) -> Real {
    let n = work.len();
    // ⌈p n / 100⌉ computed on integers where possible to avoid 95·20/100 = 19.000000000000004.
    let exact = p * n as Real;
    let rank = if exact.fract() == 0.0 && exact <= u64::MAX as Real {
        (exact as u64).div_ceil(100) as usize
    } else {
        (exact / 100.0).ceil() as usize
    };
    let index = rank.clamp(1, n) - 1;
    *work.select_nth_unstable_by(index, Real::total_cmp).1
}

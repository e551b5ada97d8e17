//! Perceptual colour maps for per-vertex scalars (distances, errors, …).

use crate::math::Real;

use super::picture::Rgb;
use super::viridis::VIRIDIS;

/// Colour used for a scalar that is not a number (no value at that vertex).
pub const NO_VALUE: Rgb = [150, 150, 150];

/// A colour map from `t ∈ [0, 1]` to a colour.
///
/// ```
/// use subdyn::render::ColorMap;
/// assert_eq!(ColorMap::Viridis.color(0.0), [68, 1, 84]);
/// assert_eq!(ColorMap::Viridis.color(1.0), [253, 231, 37]);
/// assert_eq!(ColorMap::Viridis.color(7.0), [253, 231, 37]); // clamped
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorMap {
    /// Viridis (van der Walt and Smith 2015, the matplotlib default): perceptually
    /// uniform, monotonic in lightness, readable in grey and by colour-blind viewers.
    #[default]
    Viridis,
}

impl ColorMap {
    /// The colour at `t` (clamped to `[0, 1]`) as 8-bit sRGB; [`NO_VALUE`] for NaN.
    pub fn color(self, t: Real) -> Rgb {
        if t.is_nan() {
            return NO_VALUE;
        }
        self.color_f32(t)
            .map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
    }

    /// The colour at `t` (clamped to `[0, 1]`) as sRGB in `[0, 1]`, linearly
    /// interpolated between the 256 table entries.
    pub(crate) fn color_f32(self, t: Real) -> [f32; 3] {
        if t.is_nan() {
            return NO_VALUE.map(|c| c as f32 / 255.0);
        }
        let table = match self {
            ColorMap::Viridis => &VIRIDIS,
        };
        let x = t.clamp(0.0, 1.0) * (table.len() - 1) as Real;
        let i = (x.floor() as usize).min(table.len() - 2);
        let f = (x - i as Real) as f32;
        let (a, b) = (table[i], table[i + 1]);
        [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * f)
    }
}

/// The default colour range of distances: from 0 (the colour says how far,
/// not how far beyond the nearest point) to the `p`-th percentile of the
/// finite values ([`crate::metrics::percentile`], nearest rank), so that a
/// few hot spots above it (drawn in the top colour) do not turn the rest
/// of the picture into one colour; `subdyn render` uses `p = 99`
/// ([`DISTANCE_PERCENTILE`]). `None` when no value is finite; the top is
/// raised to the largest value when the percentile is 0.
///
/// ```
/// use subdyn::render::distance_range;
/// let mut d = vec![0.1; 999];
/// d.push(50.0); // one hot spot
/// assert_eq!(distance_range(&d, 99.0), Some((0.0, 0.1)));
/// assert_eq!(distance_range(&d, 100.0), Some((0.0, 50.0)));
/// ```
pub fn distance_range(values: &[Real], p: Real) -> Option<(Real, Real)> {
    let finite: Vec<Real> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let top = crate::metrics::percentile(&finite, p)?;
    let top = if top > 0.0 {
        top
    } else {
        finite.iter().copied().fold(0.0, Real::max)
    };
    Some((0.0, top))
}

/// The percentile [`distance_range`] clips at in `subdyn render`.
pub const DISTANCE_PERCENTILE: Real = 99.0;

/// Maps a scalar to `[0, 1]` over `range` (not clamped); with a degenerate
/// range, values up to `lo` map to 0 and larger ones to 1.
pub(crate) fn normalise(value: Real, range: (Real, Real)) -> Real {
    let (lo, hi) = range;
    if hi <= lo || hi.is_nan() || lo.is_nan() {
        return if value > lo { 1.0 } else { 0.0 };
    }
    (value - lo) / (hi - lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_stays_between_neighbouring_entries() {
        let c = ColorMap::Viridis.color_f32(0.5 / 255.0);
        for k in 0..3 {
            let (a, b) = (VIRIDIS[0][k], VIRIDIS[1][k]);
            assert!(c[k] >= a.min(b) && c[k] <= a.max(b));
        }
        assert_eq!(ColorMap::Viridis.color(Real::NAN), NO_VALUE);
        assert_eq!(normalise(3.0, (2.0, 4.0)), 0.5);
        assert_eq!(normalise(2.0, (2.0, 2.0)), 0.0);
        assert_eq!(normalise(3.0, (2.0, 2.0)), 1.0);
    }
}

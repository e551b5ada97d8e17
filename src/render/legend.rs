//! The colour legend: a vertical colour bar with "nice" tick values
//! (1, 2 or 5 × 10ᵏ apart) labelled in the built-in font, and the title line.

use crate::math::Real;

use super::colormap::{ColorMap, normalise};
use super::font::{GLYPH_H, draw_text, text_width};
use super::picture::{Picture, Rgb};

/// Colour of text and tick marks.
pub(crate) const INK: Rgb = [30, 30, 30];

/// Tick values inside `range`, 1, 2 or 5 × 10ᵏ apart, about `target` of them
/// (at least two when the range is not degenerate); the range itself when
/// it is degenerate.
///
/// ```
/// use subdyn::render::nice_ticks;
/// assert_eq!(nice_ticks((0.0, 1.0), 5), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
/// assert_eq!(nice_ticks((0.013, 0.047), 4), vec![0.02, 0.03, 0.04]);
/// ```
pub fn nice_ticks(range: (Real, Real), target: usize) -> Vec<Real> {
    let (lo, hi) = range;
    if !lo.is_finite() || !hi.is_finite() || hi <= lo {
        return vec![lo];
    }
    let raw = (hi - lo) / target.max(1) as Real;
    // The step is n · 10^e with n ∈ {1, 2, 5}; values are computed as
    // k·n · 10^e or k·n / 10^-e so that 0.6 comes out as 0.6, not 0.6000000000000001.
    let mut e = raw.log10().floor() as i32;
    let mut n = 1i64;
    for m in [1, 2, 5, 10] {
        if m as Real * ten(e) >= raw {
            n = m;
            break;
        }
    }
    if n == 10 {
        (n, e) = (1, e + 1);
    }
    let value = |k: i64, n: i64, e: i32| {
        let m = (k * n) as Real;
        if e >= 0 { m * ten(e) } else { m / ten(-e) }
    };
    for _ in 0..4 {
        let step = value(1, n, e);
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        if last - first >= 1 && last - first <= 1000 {
            return (first..=last).map(|k| value(k, n, e) + 0.0).collect();
        }
        // The next smaller nice step.
        (n, e) = match n {
            1 => (5, e - 1),
            2 => (1, e),
            _ => (2, e),
        };
    }
    vec![lo, hi]
}

/// Tick values for a logarithmic axis over `range` (both ends above 0): the
/// powers of ten inside it; when those are fewer than three, also 2 and 5 ×
/// 10ᵏ; when still fewer, every m × 10ᵏ (m = 1 … 9); when still fewer (a
/// range narrower than about a factor 1.5), the linear [`nice_ticks`]. Of
/// more than `max` powers of ten every second (third, …) is kept.
///
/// ```
/// use subdyn::render::log_ticks;
/// assert_eq!(log_ticks((0.003, 2.0), 8), vec![0.01, 0.1, 1.0]);
/// assert_eq!(log_ticks((0.03, 0.6), 8), vec![0.05, 0.1, 0.2, 0.5]);
/// assert_eq!(log_ticks((1e-6, 1e6), 4), vec![1e-4, 1.0, 1e4]);
/// ```
pub fn log_ticks(range: (Real, Real), max: usize) -> Vec<Real> {
    let (lo, hi) = range;
    if !(lo > 0.0 && hi.is_finite() && hi > lo) {
        return nice_ticks(range, max.max(2));
    }
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &Real| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let value = |m: i32, e: i32| {
        if e >= 0 {
            m as Real * ten(e)
        } else {
            m as Real / ten(-e)
        }
    };
    let decades: Vec<i32> = (e0..=e1).filter(|&e| inside(&value(1, e))).collect();
    if decades.len() >= 3 {
        // Every k-th power of ten, anchored at 10⁰ when it is inside.
        let k = decades.len().div_ceil(max.max(2)).max(1) as i32;
        return decades
            .into_iter()
            .filter(|e| e.rem_euclid(k) == 0)
            .map(|e| value(1, e))
            .collect();
    }
    for mantissas in [&[1, 2, 5][..], &[1, 2, 3, 4, 5, 6, 7, 8, 9]] {
        let t: Vec<Real> = (e0..=e1)
            .flat_map(|e| mantissas.iter().map(move |&m| value(m, e)))
            .filter(inside)
            .collect();
        if t.len() >= 3 {
            return t;
        }
    }
    nice_ticks(range, 4)
}

/// Labels for [`log_ticks`]: each value in its shortest form (`0.05`, `1`,
/// `20`), in scientific notation below 10⁻³ or from 10⁵ on (`1e-6`).
///
/// ```
/// use subdyn::render::log_tick_labels;
/// assert_eq!(log_tick_labels(&[0.05, 0.1, 1.0, 20.0]), vec!["0.05", "0.1", "1", "20"]);
/// assert_eq!(log_tick_labels(&[1e-6, 1e6]), vec!["1e-6", "1e6"]);
/// ```
pub fn log_tick_labels(ticks: &[Real]) -> Vec<String> {
    ticks
        .iter()
        .map(|&t| {
            if t != 0.0 && !(1e-3..1e5).contains(&t.abs()) {
                format!("{t:e}")
            } else {
                format!("{t}")
            }
        })
        .collect()
}

/// 10^e.
fn ten(e: i32) -> Real {
    10f64.powi(e)
}

/// Labels for tick values, all with the same number of decimals (or all in
/// scientific notation when the values are very large or very small).
///
/// ```
/// use subdyn::render::tick_labels;
/// assert_eq!(tick_labels(&[0.0, 0.5, 1.0]), vec!["0.0", "0.5", "1.0"]);
/// assert_eq!(tick_labels(&[0.0, 2e-5, 4e-5]), vec!["0", "2e-5", "4e-5"]);
/// assert_eq!(tick_labels(&[-10.0, 0.0, 10.0]), vec!["-10", "0", "10"]);
/// ```
pub fn tick_labels(ticks: &[Real]) -> Vec<String> {
    let step = ticks
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(Real::INFINITY, Real::min);
    let biggest = ticks.iter().fold(0.0, |m: Real, t| m.max(t.abs()));
    let exponent = |x: Real| (x.log10() + 1e-9).floor() as i32;
    let step_exp = if step.is_finite() && step > 0.0 {
        exponent(step)
    } else if biggest > 0.0 {
        exponent(biggest).saturating_sub(2)
    } else {
        0
    };
    let scientific = biggest >= 1e5 || (biggest > 0.0 && biggest < 1e-3);
    if scientific {
        let digits = (exponent(biggest).saturating_sub(step_exp)).clamp(0, 6) as usize;
        return ticks
            .iter()
            .map(|&t| {
                if t == 0.0 {
                    "0".to_string()
                } else {
                    format!("{t:.digits$e}")
                }
            })
            .collect();
    }
    let decimals = (step_exp.saturating_neg()).clamp(0, 10) as usize;
    ticks.iter().map(|t| format!("{t:.decimals$}")).collect()
}

/// Placement of the legend in the final picture.
#[derive(Clone, Debug)]
pub(crate) struct Legend {
    pub range: (Real, Real),
    pub label: Option<String>,
    pub colormap: ColorMap,
    pub ticks: Vec<Real>,
    pub labels: Vec<String>,
    pub scale: u32,
}

impl Legend {
    /// A legend for `range` with labels at text `scale`.
    pub fn new(
        range: (Real, Real),
        label: Option<String>,
        colormap: ColorMap,
        scale: u32,
    ) -> Legend {
        let ticks = nice_ticks(range, 5);
        let labels = tick_labels(&ticks);
        Legend {
            range,
            label,
            colormap,
            ticks,
            labels,
            scale,
        }
    }

    /// Width of the colour bar in pixels.
    fn bar_width(&self) -> u32 {
        6 * self.scale + 6
    }

    /// Width in pixels the legend needs at the right side of the picture.
    pub fn width(&self) -> u32 {
        let labels = self
            .labels
            .iter()
            .map(|l| text_width(l, self.scale))
            .max()
            .unwrap_or(0);
        let pad = 4 * self.scale;
        pad + self.bar_width() + 2 * self.scale + 2 * self.scale + labels + pad
    }

    /// Draws the bar, ticks and labels in the strip `[x0, W) × [y0, y1)`.
    pub fn draw(&self, picture: &mut Picture, x0: i64, y0: i64, y1: i64) {
        let s = i64::from(self.scale);
        let text_h = i64::from(GLYPH_H) * s;
        let pad = 4 * s;
        let label_h = if self.label.is_some() {
            text_h + 2 * pad
        } else {
            0
        };
        let span = (y1 - y0 - label_h).max(0);
        let bar_h = (span * 7 / 10).max(16);
        let top = y0 + label_h + (span - bar_h) / 2;
        let bar_x = x0 + pad;
        let bar_w = i64::from(self.bar_width());
        if let Some(label) = &self.label {
            let w = i64::from(text_width(label, self.scale));
            // Centred over the bar, kept inside the picture.
            let lx = (bar_x + bar_w / 2 - w / 2)
                .min(i64::from(picture.width()) - w - 2)
                .max(0);
            draw_text(picture, lx, top - pad - text_h, label, self.scale, INK);
        }
        for row in 0..bar_h {
            let t = 1.0 - row as Real / (bar_h - 1).max(1) as Real;
            let c = self.colormap.color(t);
            picture.fill_rect(bar_x, top + row, bar_x + bar_w, top + row + 1, c);
        }
        // Frame.
        picture.fill_rect(bar_x - 1, top - 1, bar_x + bar_w + 1, top, INK);
        picture.fill_rect(
            bar_x - 1,
            top + bar_h,
            bar_x + bar_w + 1,
            top + bar_h + 1,
            INK,
        );
        picture.fill_rect(bar_x - 1, top, bar_x, top + bar_h, INK);
        picture.fill_rect(bar_x + bar_w, top, bar_x + bar_w + 1, top + bar_h, INK);
        for (tick, label) in self.ticks.iter().zip(&self.labels) {
            let t = normalise(*tick, self.range).clamp(0.0, 1.0);
            let y = top + ((1.0 - t) * (bar_h - 1) as Real).round() as i64;
            let tx = bar_x + bar_w + 1;
            picture.fill_rect(tx, y, tx + 2 * s, y + 1, INK);
            draw_text(picture, tx + 4 * s, y - text_h / 2, label, self.scale, INK);
        }
    }
}

/// Height in pixels of the title band at text `scale`.
pub(crate) fn title_height(scale: u32) -> u32 {
    GLYPH_H * scale + 8 * scale
}

/// Draws `title` centred in the top band of the picture (clipped at the sides).
pub(crate) fn draw_title(picture: &mut Picture, title: &str, scale: u32) {
    let w = i64::from(text_width(title, scale));
    let x = ((i64::from(picture.width()) - w) / 2).max(2);
    draw_text(picture, x, i64::from(4 * scale), title, scale, INK);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_lie_in_the_range_and_are_evenly_spaced() {
        for (lo, hi) in [
            (0.0, 0.0373),
            (-3.2, 7.9),
            (1e-6, 9e-6),
            (0.0, 1234.0),
            (5.0, 5.001),
        ] {
            let t = nice_ticks((lo, hi), 5);
            assert!(t.len() >= 2, "{lo}..{hi}: {t:?}");
            assert!(
                t.iter().all(|&x| x >= lo - 1e-12 && x <= hi + 1e-12),
                "{t:?}"
            );
            let labels = tick_labels(&t);
            let distinct: std::collections::HashSet<_> = labels.iter().collect();
            assert_eq!(distinct.len(), labels.len(), "{labels:?}");
        }
        assert_eq!(nice_ticks((2.0, 2.0), 5), vec![2.0]);
        assert_eq!(tick_labels(&[0.0]), vec!["0"]);
        assert_eq!(tick_labels(&[2.5]), vec!["2.50"]);
    }
}

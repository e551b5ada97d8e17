//! Line plots into a [`Picture`]: convergence curves (error against time) for
//! reports, drawn with the built-in font — no plotting dependency.

use crate::error::{Error, Result};
use crate::math::Real;

use super::legend::{draw_title, title_height};
use super::{
    ColorMap, Picture, Rgb, draw_text, log_tick_labels, log_ticks, nice_ticks, text_width,
    tick_labels,
};

/// One curve: a label, its points `(x, y)` and its colour.
#[derive(Clone, Debug)]
pub struct Series {
    /// Shown in the key.
    pub label: String,
    /// Points, drawn in order.
    pub points: Vec<(Real, Real)>,
    /// Line colour.
    pub color: Rgb,
}

/// A horizontal reference line across the plot (a tolerance), dashed, with
/// its label above its right end.
#[derive(Clone, Debug)]
pub struct HLine {
    /// Height on the y axis (above 0 on a log axis).
    pub y: Real,
    /// Drawn above the line.
    pub label: String,
    /// Line and label colour.
    pub color: Rgb,
}

/// How [`line_plot`] draws. Every field has a default (see [`Default`]).
#[derive(Clone, Debug)]
pub struct PlotOptions {
    /// A line of text centred at the top, e.g. what was measured (default none).
    pub title: Option<String>,
    /// Below the x axis (default empty).
    pub x_label: String,
    /// Above the y axis (default empty).
    pub y_label: String,
    /// Logarithmic y axis; all `y` must then be above 0 (default false).
    pub log_y: bool,
    /// Horizontal reference lines, kept inside the y range (default none).
    pub hlines: Vec<HLine>,
    /// Picture width in pixels (default 800).
    pub width: u32,
    /// Picture height in pixels (default 480).
    pub height: u32,
}

impl Default for PlotOptions {
    fn default() -> Self {
        PlotOptions {
            title: None,
            x_label: String::new(),
            y_label: String::new(),
            log_y: false,
            hlines: Vec::new(),
            width: 800,
            height: 480,
        }
    }
}

/// A plot of `series` with labelled ticks on both axes (a "nice" rule:
/// [`nice_ticks`] on a linear axis, [`log_ticks`] on a logarithmic one),
/// axis labels, the `options.hlines` and a key.
pub fn line_plot(series: &[Series], options: &PlotOptions) -> Result<Picture> {
    let (width, height, log_y) = (options.width, options.height, options.log_y);
    let pts: Vec<(Real, Real)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .collect();
    if pts.is_empty() {
        return Err(Error::input("nothing to plot"));
    }
    let bad = |x: Real, y: Real| !x.is_finite() || !y.is_finite() || (log_y && y <= 0.0);
    if pts.iter().any(|p| bad(p.0, p.1)) || options.hlines.iter().any(|h| bad(0.0, h.y)) {
        return Err(Error::input(
            "plot values must be finite (and positive on a log axis)",
        ));
    }
    let fy = |y: Real| if log_y { y.log10() } else { y };
    let (mut x0, mut x1) = (Real::INFINITY, Real::NEG_INFINITY);
    let (mut y0, mut y1) = (Real::INFINITY, Real::NEG_INFINITY);
    for &(x, y) in &pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(fy(y));
        y1 = y1.max(fy(y));
    }
    for h in &options.hlines {
        y0 = y0.min(fy(h.y));
        y1 = y1.max(fy(h.y));
    }
    if x1 - x0 < 1e-12 {
        x1 = x0 + 1.0;
    }
    if y1 - y0 < 1e-12 {
        y0 -= 0.5;
        y1 += 0.5;
    }
    let (x0, y0, y1) = (x0.min(0.0), y0 - 0.05 * (y1 - y0), y1 + 0.05 * (y1 - y0));
    let mut pic = Picture::new(width, height, [255, 255, 255])?;
    let top = match &options.title {
        Some(_) => title_height(1) as i64 + 16,
        None => 20,
    };
    let (left, right, bottom) = (70i64, width as i64 - 150, height as i64 - 45);
    if right - left < 50 || bottom - top < 50 {
        return Err(Error::input(format!(
            "plot size {width}×{height} is too small"
        )));
    }
    let sx = |x: Real| left + ((x - x0) / (x1 - x0) * (right - left) as Real).round() as i64;
    // `t` on the axis' own scale (log10 y on a log axis).
    let sy_axis = |t: Real| bottom - ((t - y0) / (y1 - y0) * (bottom - top) as Real).round() as i64;
    let sy = |y: Real| sy_axis(fy(y));
    let grey = [200, 200, 200];
    let black = [0, 0, 0];
    // Ticks and grid.
    let xt = nice_ticks((x0, x1), 6);
    for (t, label) in xt.iter().zip(tick_labels(&xt)) {
        let x = sx(*t);
        line(&mut pic, (x, top), (x, bottom), grey);
        draw_text(
            &mut pic,
            x - text_width(&label, 1) as i64 / 2,
            bottom + 6,
            &label,
            1,
            black,
        );
    }
    let (yt, ylabels) = if log_y {
        let t = log_ticks((10f64.powf(y0), 10f64.powf(y1)), 8);
        let labels = log_tick_labels(&t);
        (t, labels)
    } else {
        let t = nice_ticks((y0, y1), 6);
        let labels = tick_labels(&t);
        (t, labels)
    };
    for (t, label) in yt.iter().zip(ylabels) {
        let y = sy(*t);
        line(&mut pic, (left, y), (right, y), grey);
        draw_text(
            &mut pic,
            left - 6 - text_width(&label, 1) as i64,
            y - 3,
            &label,
            1,
            black,
        );
    }
    line(&mut pic, (left, bottom), (right, bottom), black);
    line(&mut pic, (left, top), (left, bottom), black);
    draw_text(
        &mut pic,
        (left + right) / 2 - text_width(&options.x_label, 1) as i64 / 2,
        bottom + 22,
        &options.x_label,
        1,
        black,
    );
    draw_text(&mut pic, 4, top - 14, &options.y_label, 1, black);
    if let Some(title) = &options.title {
        draw_title(&mut pic, title, 1);
    }
    // Reference lines, dashed, under the curves.
    for h in &options.hlines {
        let y = sy(h.y);
        for x in (left..right).step_by(8) {
            line(&mut pic, (x, y), ((x + 4).min(right), y), h.color);
        }
        draw_text(
            &mut pic,
            right - text_width(&h.label, 1) as i64 - 2,
            y - 10,
            &h.label,
            1,
            h.color,
        );
    }
    // Curves and key.
    for (k, s) in series.iter().enumerate() {
        for w in s.points.windows(2) {
            line(
                &mut pic,
                (sx(w[0].0), sy(w[0].1)),
                (sx(w[1].0), sy(w[1].1)),
                s.color,
            );
        }
        for &(x, y) in &s.points {
            pic.fill_rect(sx(x) - 2, sy(y) - 2, sx(x) + 3, sy(y) + 3, s.color);
        }
        let ky = top + 14 * k as i64;
        pic.fill_rect(right + 12, ky, right + 24, ky + 7, s.color);
        draw_text(&mut pic, right + 30, ky, &s.label, 1, black);
    }
    Ok(pic)
}

/// Colour `i` of `n` distinct colours along the viridis map.
pub fn series_color(i: usize, n: usize) -> Rgb {
    ColorMap::Viridis.color(if n <= 1 {
        0.0
    } else {
        0.85 * i as Real / (n - 1) as Real
    })
}

/// A one-pixel line (Bresenham 1965).
fn line(pic: &mut Picture, a: (i64, i64), b: (i64, i64), color: Rgb) {
    let (mut x, mut y) = a;
    let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
    let (sx, sy) = (
        if a.0 < b.0 { 1 } else { -1 },
        if a.1 < b.1 { 1 } else { -1 },
    );
    let mut err = dx + dy;
    loop {
        pic.set(x, y, color);
        if (x, y) == b {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
    }
}

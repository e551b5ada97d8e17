//! A top view (x, y, equal scale) of curves and control polygons as a
//! [`Picture`], for comparing an original curve with its fine-tuned one.

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::render::{Picture, Rgb, draw_text};
use crate::subdivision::CurveTopology;

use super::curve_bspline::BSplineCurve;

/// Samples per parameter unit (span) of the drawn curves.
const SAMPLES_PER_SPAN: Real = 20.0;

/// One polyline to draw: points (z ignored), colour, line width in pixels,
/// and whether to mark each point with a small square.
#[derive(Clone, Debug)]
pub struct CurveLayer {
    /// The polyline.
    pub points: Vec<Point3>,
    /// Its colour.
    pub color: Rgb,
    /// Line width in pixels (1 to 9).
    pub width: u32,
    /// Draw a 5×5 square on every point.
    pub marks: bool,
}

/// `curve` sampled at 20 points per span, drawn without marks.
pub fn curve_layer(curve: &BSplineCurve, color: Rgb, width: u32) -> CurveLayer {
    let (t0, t1) = curve.domain();
    CurveLayer {
        points: curve.samples(((t1 - t0) * SAMPLES_PER_SPAN).ceil().max(1.0) as usize),
        color,
        width,
        marks: false,
    }
}

/// The layers of a before/after picture: the control polygon `polygon`
/// (grey, marked, closed for a closed curve), its limit curve (blue) and
/// `tuned` (red).
pub fn comparison_layers(
    topology: &CurveTopology,
    polygon: &[Point3],
    tuned: &BSplineCurve,
) -> Result<Vec<CurveLayer>> {
    let steps = (SAMPLES_PER_SPAN as usize) * topology.num_spans();
    let ts: Vec<Real> = (0..=steps).map(|i| i as Real / SAMPLES_PER_SPAN).collect();
    let original = topology.limit_stencil(&ts, 0)?.apply(polygon)?;
    let mut points = polygon.to_vec();
    if topology.closed && !polygon.is_empty() {
        points.push(polygon[0]);
    }
    Ok(vec![
        CurveLayer {
            points,
            color: [170, 170, 170],
            width: 1,
            marks: true,
        },
        CurveLayer {
            points: original,
            color: [60, 90, 200],
            width: 3,
            marks: false,
        },
        curve_layer(tuned, [220, 60, 40], 3),
    ])
}

/// Draws `layers` into a `width × height` white picture with a 5 % margin
/// and a `title` line at the top.
pub fn curve_picture(
    layers: &[CurveLayer],
    title: &str,
    width: u32,
    height: u32,
) -> Result<Picture> {
    let mut picture = Picture::new(width, height, [255, 255, 255])?;
    let all: Vec<&Point3> = layers.iter().flat_map(|l| l.points.iter()).collect();
    if all.is_empty() || all.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(Error::input("nothing finite to draw"));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (Real::MAX, Real::MIN, Real::MAX, Real::MIN);
    for p in &all {
        x0 = x0.min(p.x);
        x1 = x1.max(p.x);
        y0 = y0.min(p.y);
        y1 = y1.max(p.y);
    }
    let top = 24.0;
    let (w, h) = (width as Real, height as Real - top);
    let span = (x1 - x0).max(y1 - y0).max(1e-300);
    let s = 0.9 * (w / (x1 - x0).max(span * 1e-3)).min(h / (y1 - y0).max(span * 1e-3));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let screen = |p: &Point3| (0.5 * w + s * (p.x - cx), top + 0.5 * h - s * (p.y - cy));
    for layer in layers {
        let half = (layer.width.clamp(1, 9) as i64 - 1) / 2;
        let dot = |pic: &mut Picture, x: Real, y: Real, r: i64| {
            let (px, py) = (x.round() as i64, y.round() as i64);
            pic.fill_rect(px - r, py - r, px + r + 1, py + r + 1, layer.color);
        };
        for pair in layer.points.windows(2) {
            let (a, b) = (screen(&pair[0]), screen(&pair[1]));
            let steps = (b.0 - a.0)
                .abs()
                .max((b.1 - a.1).abs())
                .ceil()
                .clamp(1.0, 1e5) as usize;
            for k in 0..=steps {
                let t = k as Real / steps as Real;
                dot(
                    &mut picture,
                    a.0 + t * (b.0 - a.0),
                    a.1 + t * (b.1 - a.1),
                    half,
                );
            }
        }
        if layer.marks {
            for p in &layer.points {
                let (x, y) = screen(p);
                dot(&mut picture, x, y, 2);
            }
        }
    }
    draw_text(&mut picture, 8, 6, title, 2, [0, 0, 0]);
    Ok(picture)
}

//! Triangle rasterisation with a z-buffer.
//!
//! Vertices are snapped to a 1/256-pixel grid and the edge functions are
//! evaluated exactly in integers, with the top-left fill rule (D3D10 /
//! OpenGL convention): a pixel centre on an edge belongs to the triangle only
//! if the edge is a top or a left edge. Two triangles sharing an edge
//! therefore cover every pixel centre along it exactly once — no cracks, no
//! double coverage.

use super::camera::ScreenPoint;

/// Sub-pixel steps per pixel (8 bits of sub-pixel precision).
const SUB: i64 = 256;
/// Vertices further than this from the origin (in pixels) are not drawn.
const LIMIT: f64 = 1.0e6;

/// A colour buffer and a depth buffer of the same size (the working
/// resolution, before down-sampling). Colours are sRGB in `[0, 1]`; depth is
/// the distance along the view axis, `+∞` where nothing was drawn; `flat`
/// marks pixels last written by an unshaded point (for eye-dome lighting).
#[derive(Clone, Debug)]
pub(crate) struct Target {
    pub width: usize,
    pub height: usize,
    pub color: Vec<[f32; 3]>,
    pub depth: Vec<f32>,
    pub flat: Vec<bool>,
}

/// What the shader learns about a covered pixel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fragment {
    /// Perspective-correct barycentric weights of the three vertices.
    pub bary: [f64; 3],
    /// True when the triangle is seen from behind (clockwise on screen for
    /// counter-clockwise-from-outside input).
    pub back: bool,
}

impl Target {
    /// A target filled with `background` and infinite depth.
    pub fn new(width: usize, height: usize, background: [f32; 3]) -> Target {
        Target {
            width,
            height,
            color: vec![background; width * height],
            depth: vec![f32::INFINITY; width * height],
            flat: vec![false; width * height],
        }
    }

    /// Writes `color` at `(x, y)` if `depth` is nearer than what is there
    /// (strictly: of two equal depths the first drawn stays). Returns whether
    /// the pixel was written.
    pub fn test_and_set(&mut self, x: usize, y: usize, depth: f32, color: [f32; 3]) -> bool {
        let i = y * self.width + x;
        if depth < self.depth[i] {
            self.depth[i] = depth;
            self.color[i] = color;
            self.flat[i] = false;
            true
        } else {
            false
        }
    }
}

/// Fills the triangle `v` into `target`, calling `shade` for every covered
/// pixel that passes the depth test. With `perspective`, attributes and depth
/// are interpolated perspective-correctly (linearly in `1/depth`).
/// Degenerate (zero-area) triangles draw nothing.
pub(crate) fn fill_triangle(
    target: &mut Target,
    v: [ScreenPoint; 3],
    perspective: bool,
    mut shade: impl FnMut(Fragment) -> [f32; 3],
) {
    if v.iter()
        .any(|p| !(p.x.abs() < LIMIT && p.y.abs() < LIMIT && p.depth.is_finite()))
    {
        return;
    }
    let snap = |p: &ScreenPoint| {
        [
            (p.x * SUB as f64).round() as i64,
            (p.y * SUB as f64).round() as i64,
        ]
    };
    let mut s = [snap(&v[0]), snap(&v[1]), snap(&v[2])];
    let mut order = [0usize, 1, 2];
    let mut area = edge(s[0], s[1], s[2]);
    if area == 0 {
        return;
    }
    // Positive area is clockwise on screen (y down): the back of a
    // counter-clockwise face. Normalise to positive area, remember the side.
    let back = area > 0;
    if area < 0 {
        s.swap(1, 2);
        order.swap(1, 2);
        area = -area;
    }
    let lo_x = (s.iter().map(|p| p[0]).min().unwrap_or(0) / SUB - 1).max(0);
    let hi_x = (s.iter().map(|p| p[0]).max().unwrap_or(0) / SUB + 1).min(target.width as i64 - 1);
    let lo_y = (s.iter().map(|p| p[1]).min().unwrap_or(0) / SUB - 1).max(0);
    let hi_y = (s.iter().map(|p| p[1]).max().unwrap_or(0) / SUB + 1).min(target.height as i64 - 1);
    if lo_x > hi_x || lo_y > hi_y {
        return;
    }
    // Edge i is opposite vertex i: from s[i+1] to s[i+2].
    let ends = [(1, 2), (2, 0), (0, 1)];
    let bias = ends.map(|(a, b)| i64::from(is_top_left(s[a], s[b])));
    let depth = order.map(|i| v[i].depth);
    let inv_depth = depth.map(|d| 1.0 / d);
    let step_x = ends.map(|(a, b)| -(s[b][1] - s[a][1]) * SUB);
    let step_y = ends.map(|(a, b)| (s[b][0] - s[a][0]) * SUB);
    let start = [lo_x * SUB + SUB / 2, lo_y * SUB + SUB / 2];
    let mut row = ends.map(|(a, b)| edge(s[a], s[b], start));
    for y in lo_y..=hi_y {
        let mut w = row;
        for x in lo_x..=hi_x {
            if (0..3).all(|i| w[i] + bias[i] > 0) {
                let l = w.map(|wi| wi as f64 / area as f64);
                let (z, bary) = if perspective {
                    let q = [0, 1, 2].map(|i| l[i] * inv_depth[i]);
                    let sum = q[0] + q[1] + q[2];
                    (1.0 / sum, q.map(|qi| qi / sum))
                } else {
                    (l[0] * depth[0] + l[1] * depth[1] + l[2] * depth[2], l)
                };
                let (xu, yu) = (x as usize, y as usize);
                let i = yu * target.width + xu;
                let z = z as f32;
                if z < target.depth[i] {
                    // Back to the caller's vertex order.
                    let mut b = [0.0; 3];
                    for k in 0..3 {
                        b[order[k]] = bary[k];
                    }
                    let color = shade(Fragment { bary: b, back });
                    target.test_and_set(xu, yu, z, color);
                }
            }
            for i in 0..3 {
                w[i] += step_x[i];
            }
        }
        for i in 0..3 {
            row[i] += step_y[i];
        }
    }
}

/// Twice the signed area of `(a, b, p)`: positive when `p` lies to the right
/// of `a → b` on a y-down screen.
fn edge(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Top edge (horizontal, interior below) or left edge (going up), for a
/// triangle of positive [`edge`] area.
fn is_top_left(a: [i64; 2], b: [i64; 2]) -> bool {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    (dy == 0 && dx > 0) || dy < 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64, depth: f64) -> ScreenPoint {
        ScreenPoint { x, y, depth }
    }

    #[test]
    fn a_square_split_in_two_covers_each_pixel_once() {
        let mut coverage = vec![0u32; 200];
        // The diagonal of the second square passes through pixel centres.
        for tri in [
            [pt(1.3, 1.7, 1.0), pt(8.6, 1.7, 1.0), pt(8.6, 8.2, 1.0)],
            [pt(1.3, 1.7, 1.0), pt(8.6, 8.2, 1.0), pt(1.3, 8.2, 1.0)],
            [pt(10.0, 0.0, 1.0), pt(20.0, 0.0, 1.0), pt(20.0, 10.0, 1.0)],
            [pt(10.0, 0.0, 1.0), pt(20.0, 10.0, 1.0), pt(10.0, 10.0, 1.0)],
        ] {
            // A fresh target per triangle so the depth test does not hide overlaps.
            let mut t = Target::new(20, 10, [1.0; 3]);
            fill_triangle(&mut t, tri, false, |_| [0.0; 3]);
            for (c, d) in coverage.iter_mut().zip(&t.depth) {
                *c += u32::from(d.is_finite());
            }
        }
        for y in 0..10 {
            for x in 0..20 {
                let inside = ((1..=8).contains(&x) && (2..=7).contains(&y)) || x >= 10;
                assert_eq!(coverage[y * 20 + x], u32::from(inside), "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn facing_follows_the_winding_on_screen() {
        let mut t = Target::new(8, 8, [1.0; 3]);
        let mut seen = Vec::new();
        // Counter-clockwise on screen (y down): the front of a CCW face.
        fill_triangle(
            &mut t,
            [pt(1.0, 6.0, 1.0), pt(6.0, 6.0, 1.0), pt(1.0, 1.0, 1.0)],
            false,
            |f| {
                seen.push(f.back);
                [0.0; 3]
            },
        );
        assert!(!seen.is_empty() && seen.iter().all(|&b| !b));
    }
}

//! Depth-tested lines (edge overlays) and disks (point splats).

use super::camera::ScreenPoint;
use super::raster::Target;

/// Draws the segment `a → b` as a line `width` pixels wide. A pixel is
/// drawn where the line is no further than `bias` (world units) behind what
/// the depth buffer holds, so edges lying on a surface stay visible while
/// edges behind it are hidden. The depth buffer is not updated.
/// With `perspective`, depth is interpolated linearly in `1/depth`.
pub(crate) fn draw_line(
    target: &mut Target,
    a: ScreenPoint,
    b: ScreenPoint,
    width: usize,
    bias: f64,
    perspective: bool,
    color: [f32; 3],
) {
    let ok = |p: &ScreenPoint| p.x.abs() < 1.0e6 && p.y.abs() < 1.0e6 && p.depth.is_finite();
    if !ok(&a) || !ok(&b) {
        return;
    }
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let steps = dx.abs().max(dy.abs()).ceil().max(1.0) as usize;
    let half = (width.max(1) as i64 - 1) / 2;
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (x, y) = (a.x + t * dx, a.y + t * dy);
        let depth = if perspective {
            1.0 / ((1.0 - t) / a.depth + t / b.depth)
        } else {
            (1.0 - t) * a.depth + t * b.depth
        };
        let (cx, cy) = (x.floor() as i64, y.floor() as i64);
        for py in cy - half..cy - half + width.max(1) as i64 {
            for px in cx - half..cx - half + width.max(1) as i64 {
                if px < 0 || py < 0 || px >= target.width as i64 || py >= target.height as i64 {
                    continue;
                }
                let i = py as usize * target.width + px as usize;
                if depth - bias <= target.depth[i] as f64 {
                    target.color[i] = color;
                }
            }
        }
    }
}

/// Draws a disk of `radius` pixels centred on `p` at `p`'s depth (depth-tested
/// and written). Pixels whose centre lies within the radius are covered; a
/// disk smaller than a pixel still covers the pixel under its centre.
/// `flat` marks the written pixels for eye-dome lighting.
pub(crate) fn draw_disk(
    target: &mut Target,
    p: ScreenPoint,
    radius: f64,
    color: [f32; 3],
    flat: bool,
) {
    if !(p.x.abs() < 1.0e6 && p.y.abs() < 1.0e6 && p.depth.is_finite()) {
        return;
    }
    let r = radius.max(0.0);
    let depth = p.depth as f32;
    let (x0, x1) = ((p.x - r).floor() as i64, (p.x + r).ceil() as i64);
    let (y0, y1) = ((p.y - r).floor() as i64, (p.y + r).ceil() as i64);
    for py in y0.max(0)..=y1.min(target.height as i64 - 1) {
        for px in x0.max(0)..=x1.min(target.width as i64 - 1) {
            let (ex, ey) = (px as f64 + 0.5 - p.x, py as f64 + 0.5 - p.y);
            if ex * ex + ey * ey <= r * r {
                mark(target, px as usize, py as usize, depth, color, flat);
            }
        }
    }
    let (cx, cy) = (p.x.floor() as i64, p.y.floor() as i64);
    if cx >= 0 && cy >= 0 && cx < target.width as i64 && cy < target.height as i64 {
        mark(target, cx as usize, cy as usize, depth, color, flat);
    }
}

/// Depth-tested write that also sets the eye-dome mark.
fn mark(target: &mut Target, x: usize, y: usize, depth: f32, color: [f32; 3], flat: bool) {
    if target.test_and_set(x, y, depth, color) {
        target.flat[y * target.width + x] = flat;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_behind_a_surface_is_hidden_and_one_on_it_is_drawn() {
        let mut t = Target::new(10, 3, [1.0; 3]);
        t.depth.iter_mut().for_each(|d| *d = 5.0);
        let at = |x, depth| ScreenPoint { x, y: 1.5, depth };
        draw_line(&mut t, at(0.5, 9.0), at(9.5, 9.0), 1, 0.01, false, [0.0; 3]);
        assert!(t.color.iter().all(|c| *c == [1.0; 3]));
        draw_line(&mut t, at(0.5, 5.0), at(9.5, 5.0), 1, 0.01, false, [0.0; 3]);
        assert_eq!(t.color.iter().filter(|c| **c == [0.0; 3]).count(), 10);
    }

    #[test]
    fn a_disk_covers_the_pixels_within_its_radius() {
        let mut t = Target::new(20, 20, [1.0; 3]);
        draw_disk(
            &mut t,
            ScreenPoint {
                x: 10.0,
                y: 10.0,
                depth: 1.0,
            },
            3.0,
            [0.0; 3],
            false,
        );
        let covered = t.depth.iter().filter(|d| d.is_finite()).count();
        // Pixel centres (i + 0.5, j + 0.5) within 3 of (10, 10): 32 of them.
        assert_eq!(covered, 32);
    }
}

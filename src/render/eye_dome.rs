//! Eye-dome lighting for points without normals: a screen-space shading
//! that darkens a pixel by how much its neighbours stand in front of it
//! (Boucheny, "Visualisation scientifique de grands volumes de données",
//! PhD thesis, 2009; the point-cloud shader of CloudCompare and Potree).
//!
//! For a pixel `p` with normalised depth `z(p) ∈ [0, 1]` and its eight
//! neighbours `q` at distance `r` pixels, `response = Σ max(0, z(p) − z(q))`
//! and the colour is scaled by `exp(−strength · response)`. Tilted
//! surfaces get darker, depth jumps get dark outlines, and a flat scan
//! reads as a shaded shape.

use super::raster::Target;

/// Applies eye-dome lighting to the pixels marked in `target.flat`.
/// `radius` is the neighbour distance in working pixels; the strength is
/// chosen from the target's size so the look does not depend on resolution.
pub(crate) fn eye_dome(target: &mut Target, radius: usize) {
    if !target.flat.iter().any(|&f| f) {
        return;
    }
    let (lo, hi) = target
        .depth
        .iter()
        .filter(|d| d.is_finite())
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| {
            (a.min(d), b.max(d))
        });
    if hi <= lo || hi.is_nan() || lo.is_nan() {
        return;
    }
    let (w, h) = (target.width as i64, target.height as i64);
    let r = radius.max(1) as i64;
    // A surface tilted 60° away from the eye comes out at about half brightness.
    let strength = 0.15 * w.min(h) as f32 / r as f32;
    let z = |i: usize| (target.depth[i] - lo) / (hi - lo);
    let offsets = [
        (-1, -1),
        (0, -1),
        (1, -1),
        (-1, 0),
        (1, 0),
        (-1, 1),
        (0, 1),
        (1, 1),
    ];
    let mut shade = vec![1.0f32; target.color.len()];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if !target.flat[i] {
                continue;
            }
            let zp = z(i);
            let mut response = 0.0;
            for (dx, dy) in offsets {
                let (qx, qy) = (x + dx * r, y + dy * r);
                if qx < 0 || qy < 0 || qx >= w || qy >= h {
                    continue;
                }
                let q = (qy * w + qx) as usize;
                if target.depth[q].is_finite() {
                    response += (zp - z(q)).max(0.0);
                }
            }
            shade[i] = (-strength * response).exp();
        }
    }
    for (c, s) in target.color.iter_mut().zip(&shade) {
        *c = c.map(|x| x * s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_far_pixel_beside_a_near_one_is_darkened_and_a_plane_facing_the_eye_is_not() {
        let mut t = Target::new(5, 1, [1.0; 3]);
        t.depth = vec![1.0, 1.0, 1.0, 2.0, 2.0];
        t.flat = vec![true; 5];
        eye_dome(&mut t, 1);
        assert_eq!(t.color[0], [1.0; 3]);
        assert_eq!(t.color[1], [1.0; 3]);
        assert!(t.color[3][0] < 0.9);
        assert_eq!(t.color[4], [1.0; 3]);
    }
}

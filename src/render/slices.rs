//! Volume slices with recovered contours drawn over them: the picture a
//! person checks a segmentation with.

use super::font::{GLYPH_H, draw_text};
use super::picture::{Picture, Rgb};
use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::volume::Volume;

/// Largest side of a slice picture in pixels.
const MAX_SLICE_SIDE: Real = 1024.0;

/// The world slice `x[axis] = at` (axis 0: sagittal, 1: coronal, 2: axial)
/// of `volume` in grey (the slice's 0.5th to 99.5th percentile mapped to
/// black..white, nearest sample; black outside the volume), in the
/// radiological convention, world coordinates taken as RAS+ (NIfTI's):
/// axial and coronal slices show the subject's right on the picture's left,
/// axial slices anterior up, coronal and sagittal slices superior up,
/// sagittal slices anterior on the left. The sides are marked with their
/// letters (R/L, A/P, S/I) and the slice is labelled with its position in
/// world units (`unit`, e.g. "mm"; may be empty). A side is about `size`
/// pixels, with square world-space pixels. The curves where each surface of
/// `overlays` (world coordinates) cuts the plane are drawn over it in its
/// colour, 2 pixels wide. Oblique volumes are resliced along the world
/// axes.
pub fn slice_overlay(
    volume: &Volume,
    axis: usize,
    at: Real,
    size: u32,
    overlays: &[(&PolyMesh, Rgb)],
    unit: &str,
) -> Result<Picture> {
    let dims = volume.dims();
    if axis > 2 {
        return Err(Error::input(format!(
            "slice axis {axis} is not 0 (sagittal), 1 (coronal) or 2 (axial)"
        )));
    }
    // The world box of the voxels (their faces, half a sample beyond the
    // centres).
    let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
    for corner in 0..8 {
        let c = [0, 1, 2].map(|k| {
            if corner & (1 << k) == 0 {
                -0.5
            } else {
                dims[k] as Real - 0.5
            }
        });
        let w = volume.world(c);
        for k in 0..3 {
            lo[k] = lo[k].min(w[k]);
            hi[k] = hi[k].max(w[k]);
        }
    }
    if !(at >= lo[axis] && at <= hi[axis]) {
        return Err(Error::input(format!(
            "slice {}{at} is outside the volume ({} to {})",
            ["x = ", "y = ", "z = "][axis],
            lo[axis],
            hi[axis]
        )));
    }
    // Across (left to right) and down (top to bottom): which world axis,
    // and the letters of the sides.
    let (across, down, sides) = match axis {
        0 => (1, 2, ["A", "P", "S", "I"]),
        1 => (0, 2, ["R", "L", "S", "I"]),
        _ => (0, 1, ["R", "L", "A", "P"]),
    };
    let (wa, wb) = (hi[across] - lo[across], hi[down] - lo[down]);
    let scale = (size.max(16) as Real / wa.max(wb)).min(MAX_SLICE_SIDE / wa.max(wb));
    let (w, h) = (
        (wa * scale).round().max(1.0) as u32,
        (wb * scale).round().max(1.0) as u32,
    );
    // Both picture axes run from the world maximum down (R, A, S first).
    let world_of = |x: Real, y: Real| {
        let mut p = [0.0; 3];
        p[axis] = at;
        p[across] = hi[across] - x / scale;
        p[down] = hi[down] - y / scale;
        crate::math::Point3::from(p)
    };
    let to_px = |p: &crate::math::Point3| {
        (
            (hi[across] - p[across]) * scale,
            (hi[down] - p[down]) * scale,
        )
    };
    let sample = |p: crate::math::Point3| -> Option<f32> {
        let c = volume.continuous_index(&p);
        let i: Option<Vec<usize>> = (0..3)
            .map(|k| {
                let r = c[k].round();
                (r >= 0.0 && r < dims[k] as Real).then_some(r as usize)
            })
            .collect();
        i.map(|i| volume.at(i[0], i[1], i[2]))
    };
    let grid: Vec<Option<f32>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| sample(world_of(x as Real + 0.5, y as Real + 0.5)))
        .collect();
    let mut values: Vec<f32> = grid.iter().flatten().copied().collect();
    values.sort_by(|x, y| x.total_cmp(y));
    let pick = |q: Real| {
        values
            .get(((values.len().max(1) - 1) as Real * q) as usize)
            .map_or(0.0, |&v| v as Real)
    };
    let (vlo, vhi) = (pick(0.005), pick(0.995));
    let span = if vhi > vlo { vhi - vlo } else { 1.0 };
    let pixels = grid
        .iter()
        .map(|v| match v {
            Some(v) => {
                let g = ((*v as Real - vlo) / span).clamp(0.0, 1.0);
                let g = (g * 255.0).round() as u8;
                [g, g, g]
            }
            None => [0, 0, 0],
        })
        .collect();
    let mut picture = Picture::from_pixels(w, h, pixels)?;
    for (mesh, color) in overlays {
        for f in 0..mesh.num_faces() {
            let face = mesh.face(f);
            for k in 1..face.len().saturating_sub(1) {
                let tri = [face[0], face[k], face[k + 1]]
                    .map(|v| mesh.positions[v as usize].coords.into());
                if let Some((p, q)) = plane_cut(&tri, axis, at) {
                    draw_segment(&mut picture, to_px(&p.into()), to_px(&q.into()), *color);
                }
            }
        }
    }
    let cyan = [0, 255, 255];
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    // Rounded first, and `+ 0.0`, so that a small negative prints as 0.0.
    let label = format!(
        "{} {} = {:.1}{unit}",
        ["sagittal", "coronal", "axial"][axis],
        ["x", "y", "z"][axis],
        (10.0 * at).round() / 10.0 + 0.0
    );
    draw_text(&mut picture, 6, 6, &label, 2, cyan);
    let glyph = (GLYPH_H * 2) as i64;
    let (wi, hi_px) = (w as i64, h as i64);
    draw_text(&mut picture, 6, hi_px / 2 - glyph / 2, sides[0], 2, cyan);
    draw_text(
        &mut picture,
        wi - 16,
        hi_px / 2 - glyph / 2,
        sides[1],
        2,
        cyan,
    );
    draw_text(&mut picture, wi / 2 - 5, 6 + glyph + 4, sides[2], 2, cyan);
    draw_text(
        &mut picture,
        wi / 2 - 5,
        hi_px - glyph - 6,
        sides[3],
        2,
        cyan,
    );
    Ok(picture)
}

/// The segment where triangle `tri` meets the plane `c[axis] = level`, if
/// it does.
fn plane_cut(tri: &[[Real; 3]; 3], axis: usize, level: Real) -> Option<([Real; 3], [Real; 3])> {
    let d = tri.map(|c| c[axis] - level);
    let mut pts = Vec::with_capacity(2);
    for e in 0..3 {
        let (i, j) = (e, (e + 1) % 3);
        if (d[i] < 0.0) != (d[j] < 0.0) {
            let t = d[i] / (d[i] - d[j]);
            pts.push([0, 1, 2].map(|k| tri[i][k] + t * (tri[j][k] - tri[i][k])));
        }
    }
    (pts.len() == 2).then(|| (pts[0], pts[1]))
}

/// A 2-pixel-wide line.
fn draw_segment(picture: &mut Picture, a: (Real, Real), b: (Real, Real), color: Rgb) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
    for s in 0..=steps {
        let t = s as Real / steps as Real;
        let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        let (x, y) = (x.floor() as i64, y.floor() as i64);
        picture.set(x, y, color);
        picture.set(x + 1, y, color);
        picture.set(x, y + 1, color);
    }
}

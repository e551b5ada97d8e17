//! Volume slices with recovered contours drawn over them: the picture a
//! person checks a segmentation with.

use super::font::draw_text;
use super::picture::{Picture, Rgb};
use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::volume::Volume;

/// Largest side of a slice picture in pixels.
const MAX_SLICE_SIDE: Real = 1024.0;

/// Slice `index` across index axis `axis` (0 = x, 1 = y, 2 = z) of `volume`
/// in grey (the slice's 0.5th to 99.5th percentile mapped to black..white),
/// scaled so a side is about `size` pixels with square world-space pixels,
/// and the curves where each surface of `overlays` cuts the slice plane
/// drawn over it in its colour, 2 pixels wide. The picture's columns follow
/// the lower remaining axis and its rows the higher one, row 0 at index 0
/// (so a z slice shows x across and y down, as slice images store it).
pub fn slice_overlay(
    volume: &Volume,
    axis: usize,
    index: usize,
    size: u32,
    overlays: &[(&PolyMesh, Rgb)],
) -> Result<Picture> {
    let dims = volume.dims();
    if axis > 2 || index >= dims[axis] {
        return Err(Error::Input(format!(
            "slice {index} across axis {axis} is outside the {}×{}×{} volume",
            dims[0], dims[1], dims[2]
        )));
    }
    let (a, b) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let spacing = volume.spacing();
    let (wa, wb) = (dims[a] as Real * spacing[a], dims[b] as Real * spacing[b]);
    let scale = (size.max(16) as Real / wa.max(wb)).min(MAX_SLICE_SIDE / wa.max(wb));
    let (w, h) = (
        (wa * scale).round().max(1.0) as u32,
        (wb * scale).round().max(1.0) as u32,
    );
    let at = |i: usize, j: usize| {
        let mut c = [0; 3];
        c[axis] = index;
        c[a] = i;
        c[b] = j;
        volume.at(c[0], c[1], c[2])
    };
    let mut values: Vec<f32> = (0..dims[b])
        .flat_map(|j| (0..dims[a]).map(move |i| (i, j)))
        .map(|(i, j)| at(i, j))
        .collect();
    values.sort_by(|x, y| x.total_cmp(y));
    let pick = |q: Real| values[((values.len() - 1) as Real * q) as usize] as Real;
    let (lo, hi) = (pick(0.005), pick(0.995));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            // Pixel centre → fractional index, nearest sample.
            let i = (((x as Real + 0.5) / scale / spacing[a]) as usize).min(dims[a] - 1);
            let j = (((y as Real + 0.5) / scale / spacing[b]) as usize).min(dims[b] - 1);
            let g = ((at(i, j) as Real - lo) / span).clamp(0.0, 1.0);
            let g = (g * 255.0).round() as u8;
            pixels.push([g, g, g]);
        }
    }
    let mut picture = Picture::from_pixels(w, h, pixels)?;
    // Index (fractional) → pixel: voxel centres sit at (i + ½) voxels.
    let to_px = |c: [Real; 3]| {
        (
            (c[a] + 0.5) * spacing[a] * scale,
            (c[b] + 0.5) * spacing[b] * scale,
        )
    };
    for (mesh, color) in overlays {
        let idx: Vec<[Real; 3]> = mesh
            .positions
            .iter()
            .map(|p| volume.continuous_index(p))
            .collect();
        for f in 0..mesh.num_faces() {
            let face = mesh.face(f);
            for k in 1..face.len().saturating_sub(1) {
                let tri = [face[0], face[k], face[k + 1]].map(|v| idx[v as usize]);
                if let Some((p, q)) = plane_cut(&tri, axis, index as Real) {
                    draw_segment(&mut picture, to_px(p), to_px(q), *color);
                }
            }
        }
    }
    let label = format!("{} = {index}", ["x", "y", "z"][axis]);
    draw_text(&mut picture, 6, 6, &label, 2, [0, 255, 255]);
    Ok(picture)
}

/// The segment where triangle `tri` (in index coordinates) meets the plane
/// `c[axis] = level`, if it does.
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

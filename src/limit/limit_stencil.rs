//! Limit positions of all vertices of a refinement level, as one stencil table.

use crate::error::Result;
use crate::stencil::{RowBuilder, StencilTable};
use crate::subdivision::Hierarchy;
use crate::topology::{Level, Sharpness, VertexRule};

use super::local_eval::evaluate_face;
use super::param::CORNERS;
use super::vertex_masks::{limit_position_mask, masks_apply};

/// Rows = limit positions of the vertices of level `level`, as weights over
/// the level-0 control points. Where the vertex masks apply (quads around the
/// vertex, no semi-sharp feature at it, not a dart) the mask of
/// `vertex_masks` is used. Elsewhere, when `h` holds level `level + 1` and
/// the masks apply to the vertex's vertex point there (one step turns
/// n-gons into quads and lowers semi-sharpness by 1), the limit point is
/// that child's, its mask carried back through the subdivision rows.
/// Otherwise the vertex is a corner of one of its faces and the limit point
/// is evaluated there by local subdivision, which follows semi-sharp creases
/// until they have decayed.
pub fn limit_stencil(h: &Hierarchy, level: usize) -> Result<StencilTable> {
    let (lv, sh) = (h.level(level), &h.sharpness[level]);
    let masked = |lv: &Level, sh: &Sharpness, v: usize| {
        lv.vertex_faces(v).is_empty()
            || (masks_apply(lv, sh, v) && sh.rule(lv, v) != VertexRule::Dart)
    };
    let child = (level < h.num_levels()).then(|| {
        (
            h.level(level + 1),
            &h.sharpness[level + 1],
            h.stencil(level),
            lv.num_faces() + lv.num_edges(),
        )
    });
    let rows = StencilTable::from_row_fn(lv.num_vertices, lv.num_vertices, |v, b| {
        if masked(lv, sh, v) {
            limit_position_mask(lv, sh, v, 1.0, b);
            return;
        }
        if let Some((l1, s1, step, first)) = child
            && masked(l1, s1, first + v)
        {
            let mut mask = RowBuilder::default();
            limit_position_mask(l1, s1, first + v, 1.0, &mut mask);
            for (c, x) in mask.entries() {
                let (cols, ws) = step.row(c as usize);
                for (&c, &w) in cols.iter().zip(ws) {
                    b.add(c, x * w);
                }
            }
            return;
        }
        let f = lv.vertex_faces(v)[0] as usize;
        let fv = lv.face_vertices(f);
        let i = fv.iter().position(|&x| x as usize == v).unwrap_or(0);
        let (u, w) = if fv.len() == 4 {
            (CORNERS[i][0], CORNERS[i][1])
        } else {
            // Corner i of an n-gon is the origin of its sub-face tile.
            let d = (fv.len() as f64).sqrt().ceil() as usize;
            ((i % d) as f64, (i / d) as f64)
        };
        let s = evaluate_face(lv, sh, f, u, w);
        for (&c, &x) in s.cols.iter().zip(&s.weights[0]) {
            if x != 0.0 {
                b.add(c, x);
            }
        }
    });
    rows.compose(&h.stencil_to_level(level)?)
}

/// Limit tangents of the vertices of level `level`, as two tables of weights
/// over the level-0 control points: row `v` of the first is the derivative of
/// the limit surface at vertex `v` along the leading edge of `v`'s first ring
/// face (its first face counter-clockwise, starting at a boundary edge on a
/// boundary), the second along that face's trailing edge at `v`; both per unit
/// of that face's parameter (for an n-gon, of its quad sub-face). At a regular
/// vertex these are the exact derivatives of the bicubic patch; at an
/// extraordinary vertex they follow the corner convention of
/// [`LimitEvaluator`](super::LimitEvaluator) (they span the tangent plane).
/// Rows of isolated vertices are empty.
pub fn limit_tangent_stencils(h: &Hierarchy, level: usize) -> Result<(StencilTable, StencilTable)> {
    let (lv, sh) = (h.level(level), &h.sharpness[level]);
    let tangent = |which: usize| {
        StencilTable::from_row_fn(lv.num_vertices, lv.num_vertices, |v, b| {
            let ring = lv.vertex_ring(v);
            let Some(&f) = ring.faces.first() else { return };
            let f = f as usize;
            let fv = lv.face_vertices(f);
            let i = fv.iter().position(|&x| x as usize == v).unwrap_or(0);
            let (u, w, dirs) = if fv.len() == 4 {
                let c = CORNERS[i];
                let lead = [
                    CORNERS[(i + 1) % 4][0] - c[0],
                    CORNERS[(i + 1) % 4][1] - c[1],
                ];
                let trail = [
                    CORNERS[(i + 3) % 4][0] - c[0],
                    CORNERS[(i + 3) % 4][1] - c[1],
                ];
                (c[0], c[1], [lead, trail])
            } else {
                // Sub-face i: s = 2 (u − tu) runs along the leading edge, t along the trailing one.
                let d = (fv.len() as f64).sqrt().ceil() as usize;
                ((i % d) as f64, (i / d) as f64, [[0.5, 0.0], [0.0, 0.5]])
            };
            let s = evaluate_face(lv, sh, f, u, w);
            let dir = dirs[which];
            for (k, &c) in s.cols.iter().enumerate() {
                let x = dir[0] * s.weights[1][k] + dir[1] * s.weights[2][k];
                if x != 0.0 {
                    b.add(c, x);
                }
            }
        })
    };
    let to_zero = h.stencil_to_level(level)?;
    Ok((tangent(0).compose(&to_zero)?, tangent(1).compose(&to_zero)?))
}

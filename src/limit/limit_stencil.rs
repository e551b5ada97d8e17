//! Limit positions of all vertices of a refinement level, as one stencil table.

use crate::error::Result;
use crate::stencil::StencilTable;
use crate::subdivision::Hierarchy;
use crate::topology::VertexRule;

use super::patch::{CORNERS, evaluate_face};
use super::vertex_masks::{limit_position_mask, masks_apply};

/// Rows = limit positions of the vertices of level `level`, as weights over
/// the level-0 control points. Where the vertex masks apply (quads around the
/// vertex, no semi-sharp feature at it, not a dart) the mask of
/// `vertex_masks` is used; elsewhere the vertex is a corner of one of its faces and the limit point
/// is evaluated there by local subdivision, which follows semi-sharp creases
/// until they have decayed.
pub fn limit_stencil(h: &Hierarchy, level: usize) -> Result<StencilTable> {
    let (lv, sh) = (h.level(level), &h.sharpness[level]);
    let rows = StencilTable::from_row_fn(lv.num_vertices, lv.num_vertices, |v, b| {
        let dart = sh.rule(lv, v) == VertexRule::Dart;
        if lv.vertex_faces(v).is_empty() || (masks_apply(lv, sh, v) && !dart) {
            limit_position_mask(lv, sh, v, 1.0, b);
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

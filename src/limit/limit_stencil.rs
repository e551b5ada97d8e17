//! Limit positions of all vertices of a refinement level, as one stencil table.

use crate::error::Result;
use crate::stencil::{RowBuilder, StencilTable};
use crate::subdivision::Hierarchy;

use super::vertex_masks::{limit_position_mask, masks_apply};

/// Rows = limit positions of the vertices of level `level`, as weights over
/// the level-0 control points (limit masks in the module docs of
/// `vertex_masks`). Where a vertex's mask does not apply yet (non-quad faces
/// or a semi-sharp feature at it) the vertex is followed to finer levels — its
/// vertex point has the same limit — until it does.
pub fn limit_stencil(h: &Hierarchy, level: usize) -> Result<StencilTable> {
    let mut h = h.clone();
    h.levels.truncate(level + 1);
    h.sharpness.truncate(level + 1);
    h.stencils.truncate(level);
    let n = h.level(level).num_vertices;
    // For every vertex of `level`, the level at which its mask applies.
    let mut at = level;
    let mut idx: Vec<u32> = (0..n as u32).collect();
    let mut done: Vec<Option<(usize, u32)>> = vec![None; n];
    loop {
        let (lv, sh) = (&h.levels[at], &h.sharpness[at]);
        let mut pending = false;
        for v in 0..n {
            if done[v].is_none() {
                if masks_apply(lv, sh, idx[v] as usize) || lv.vertex_faces(idx[v] as usize).is_empty() {
                    done[v] = Some((at, idx[v]));
                } else {
                    pending = true;
                }
            }
        }
        if !pending || at >= level + 12 {
            break;
        }
        let off = (lv.num_faces() + lv.num_edges()) as u32;
        for i in idx.iter_mut() {
            *i += off;
        }
        h.push_level();
        at += 1;
    }
    // One table per finest level used: limit rows over that level's vertices,
    // composed down to level 0.
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    let mut finest_needed = level;
    for d in done.iter().flatten() {
        finest_needed = finest_needed.max(d.0);
    }
    for l in level..=finest_needed {
        let members: Vec<usize> = (0..n).filter(|&v| matches!(done[v], Some((a, _)) if a == l)).collect();
        if members.is_empty() {
            continue;
        }
        let mut b = RowBuilder::default();
        let mut t = StencilTable::with_capacity(h.levels[l].num_vertices, members.len(), 0);
        for &v in &members {
            b.clear();
            let (_, i) = done[v].unwrap_or((l, v as u32));
            limit_position_mask(&h.levels[l], &h.sharpness[l], i as usize, 1.0, &mut b);
            t.push_row(b.entries());
        }
        let to_zero = h.stencil_to_level(l)?;
        let composed = t.compose(&to_zero)?;
        for (k, &v) in members.iter().enumerate() {
            let (c, w) = composed.row(k);
            rows[v] = c.iter().copied().zip(w.iter().copied()).collect();
        }
    }
    Ok(StencilTable::from_rows(h.level(0).num_vertices, &rows))
}

//! Building a [`PatchTable`]: the regular patches' grid rows, the patches'
//! place in their base faces, the lazy quadtrees of irregular faces, and
//! moving the control points.

use super::{Patch, PatchTable, QuadtreeCache};
use rayon::prelude::*;
use std::sync::OnceLock;

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;
use crate::subdivision::{Hierarchy, Refiner};

use crate::limit::LimitEvaluator;
use crate::limit::local_eval::patch_grid;
use crate::limit::param::CORNERS;
use crate::limit::vertex_masks::{CornerKind, corner_kind};

impl PatchTable {
    /// Refines to `level` (1 to 6) and builds the regular patches.
    pub fn new(refiner: &Refiner, positions: &[Point3], level: usize) -> Result<PatchTable> {
        Self::with_quadtrees(refiner, positions, level, QuadtreeCache::default())
    }

    /// [`new`](Self::new) with quadtrees looked up in and added to `shapes`.
    pub fn with_quadtrees(
        refiner: &Refiner,
        positions: &[Point3],
        level: usize,
        shapes: QuadtreeCache,
    ) -> Result<PatchTable> {
        if level == 0 || level > 6 {
            return Err(Error::input(format!(
                "patch level {level} must be between 1 and 6"
            )));
        }
        if positions.len() != refiner.level.num_vertices {
            return Err(Error::size_mismatch(format!(
                "{} positions for a mesh of {} vertices",
                positions.len(),
                refiner.level.num_vertices
            )));
        }
        crate::limit::evaluator::check_ring_sizes(&refiner.level)?;
        let h = refiner.refine_uniform(level)?;
        let fine = h.finest();
        let sharp = h.sharpness.last().expect("levels exist");
        let maps = param_maps(&h);
        // A smooth corner is smooth in every face around its vertex (the
        // kind then depends on the vertex alone): each vertex is classified
        // once, and only the other corners face by face.
        let smooth: Vec<bool> = (0..fine.num_vertices)
            .into_par_iter()
            .map(|v| {
                fine.vertex_faces(v)
                    .first()
                    .is_some_and(|&f| corner_kind(fine, sharp, v, f) == CornerKind::Smooth)
            })
            .collect();
        let regular: Vec<bool> = (0..fine.num_faces())
            .into_par_iter()
            .map(|f| {
                fine.face_vertices(f).iter().all(|&c| {
                    smooth[c as usize]
                        || corner_kind(fine, sharp, c as usize, f as u32) != CornerKind::Irregular
                })
            })
            .collect();
        // Each face's 16 rows (empty at an irregular face): their ends,
        // columns and weights, made in parallel and then laid end to end.
        let grids: Vec<([usize; 16], Vec<u32>, Vec<Real>)> = (0..fine.num_faces())
            .into_par_iter()
            .map(|f| {
                let (mut ends, mut cols, mut weights) = ([0; 16], Vec::new(), Vec::new());
                if regular[f] {
                    for (end, row) in ends.iter_mut().zip(patch_grid(fine, sharp, f)) {
                        for (c, w) in row.entries() {
                            cols.push(c);
                            weights.push(w);
                        }
                        *end = cols.len();
                    }
                }
                (ends, cols, weights)
            })
            .collect();
        let mut grid_table = StencilTable::with_capacity(
            fine.num_vertices,
            16 * grids.len(),
            grids.iter().map(|g| g.1.len()).sum(),
        );
        for (ends, cols, weights) in grids {
            let first = grid_table.indices.len();
            grid_table.offsets.extend(ends.map(|e| first + e));
            grid_table.indices.extend(cols);
            grid_table.weights.extend(weights);
        }
        let patches = maps
            .into_iter()
            .zip(&regular)
            .map(|((base, origin, axes), &regular)| Patch {
                regular,
                tree: OnceLock::new(),
                base,
                origin,
                axes,
            })
            .collect();
        let mut table = PatchTable {
            evaluator: LimitEvaluator::new(refiner),
            level: fine.clone(),
            sharp: sharp.clone(),
            to_level: h.stencil_to_level(level)?,
            grid_table,
            positions: Vec::new(),
            level_positions: Vec::new(),
            grid_points: Vec::new(),
            offsets: h.levels[..level]
                .iter()
                .map(|l| l.face_offsets.clone())
                .collect(),
            patches,
            shapes,
        };
        table.set_positions(positions)?;
        Ok(table)
    }

    /// Moves the control points (same topology): two sparse products; the
    /// quadtrees built so far are kept.
    pub fn set_positions(&mut self, positions: &[Point3]) -> Result<()> {
        crate::mesh::check_finite(positions)?;
        if positions.len() != self.to_level.num_cols {
            return Err(Error::size_mismatch(format!(
                "{} control points for a patch table over {}",
                positions.len(),
                self.to_level.num_cols
            )));
        }
        // Into the buffers already there (sized on the first call): fresh
        // ones would be zeroed and faulted in on one thread.
        self.level_positions
            .resize(self.to_level.num_rows(), Point3::origin());
        self.grid_points
            .resize(self.grid_table.num_rows(), Point3::origin());
        self.to_level
            .apply_into(positions, &mut self.level_positions);
        self.grid_table
            .apply_into(&self.level_positions, &mut self.grid_points);
        self.patches.par_iter_mut().for_each(|patch| {
            if let Some(tree) = patch.tree.get_mut() {
                for points in &mut tree.points {
                    points.take();
                }
            }
        });
        self.positions.clear();
        self.positions.extend_from_slice(positions);
        Ok(())
    }
}

/// For every face of the finest level: its base face and the affine map from
/// its `(s, t)` to the base face's `(u, v)`.
fn param_maps(h: &Hierarchy) -> Vec<(u32, [Real; 2], [[Real; 2]; 2])> {
    let l0 = h.level(0);
    let mut maps: Vec<(u32, [Real; 2], [[Real; 2]; 2])> = (0..l0.num_faces() as u32)
        .map(|f| (f, [0.0, 0.0], [[1.0, 0.0], [0.0, 1.0]]))
        .collect();
    for k in 0..h.num_levels() {
        let parent = h.level(k);
        let mut next = Vec::with_capacity(parent.face_verts.len());
        for (f, &(base, o, a)) in maps.iter().enumerate() {
            let n = parent.face_vertices(f).len();
            for i in 0..n {
                if n != 4 {
                    // n-gon sub-face i: its tile, at half scale (only at level 0).
                    let d = (n as Real).sqrt().ceil() as usize;
                    next.push((
                        base,
                        [(i % d) as Real, (i / d) as Real],
                        [[0.5, 0.0], [0.0, 0.5]],
                    ));
                    continue;
                }
                // Child i: corner 0 at parent corner i, s towards i+1, t towards i−1.
                let c = CORNERS[i];
                let ax = [
                    CORNERS[(i + 1) % 4][0] - c[0],
                    CORNERS[(i + 1) % 4][1] - c[1],
                ];
                let bx = [
                    CORNERS[(i + 3) % 4][0] - c[0],
                    CORNERS[(i + 3) % 4][1] - c[1],
                ];
                // parent (s, t) = c + ½ (ax s' + bx t'); base = o + a · parent.
                let po = [
                    o[0] + a[0][0] * c[0] + a[0][1] * c[1],
                    o[1] + a[1][0] * c[0] + a[1][1] * c[1],
                ];
                let col = |v: [Real; 2]| {
                    [
                        0.5 * (a[0][0] * v[0] + a[0][1] * v[1]),
                        0.5 * (a[1][0] * v[0] + a[1][1] * v[1]),
                    ]
                };
                let (cs, ct) = (col(ax), col(bx));
                next.push((base, po, [[cs[0], ct[0]], [cs[1], ct[1]]]));
            }
        }
        maps = next;
    }
    maps
}

//! Embedding model vertices in the cells of a refined lattice: the weight
//! table `W` of `v = W P_n` (MacCracken & Joy 1996, §4–5: each point is
//! "tagged" with its cell of `L_n` and its parameters in the cell).

use std::collections::HashSet;

use rayon::prelude::*;

use crate::lattice::{LatticeTopology, TypeNCells};
use crate::math::{Point3, Real, bbox_diagonal};
use crate::stencil::StencilTable;

use super::cell_coords::{CellCoords, cell_coords};
use super::cell_index::CellIndex;

/// Result of embedding points in a refined level.
#[derive(Clone, Debug)]
pub struct Embedding {
    /// `W`: one row per point over the level's vertices; empty rows for
    /// points outside the lattice.
    pub weights: StencilTable,
    /// Cell of every point (`u32::MAX` outside).
    pub cell: Vec<u32>,
    /// Points found in no cell.
    pub outside: Vec<u32>,
    /// Points taken into the nearest candidate cell although slightly
    /// outside every cell (gaps between bilinear and triangulated faces).
    pub snapped: usize,
    /// Largest number of Newton iterations used.
    pub max_newton_iterations: usize,
    /// Points in type-n (non-hexahedral) cells.
    pub in_type_n_cells: usize,
}

/// Embeds `points` in the cells of a refined level (topology `topo`,
/// positions `x`). A point is inside a cell when its coordinates violate the
/// cell's bounds by at most `1e-9`; otherwise the candidate with the
/// smallest violation is taken when that is below `slack` (parameter units)
/// and the face it lies beyond is not on the lattice's boundary (so the
/// deformable region keeps its exact boundary), else the point is outside.
pub fn embedding(
    topo: &LatticeTopology,
    cells: &TypeNCells,
    x: &[Point3],
    points: &[Point3],
    slack: Real,
) -> Embedding {
    let boundary: Vec<[u32; 4]> = topo
        .boundary_faces()
        .iter()
        .filter_map(|&f| topo.faces.row(f as usize).try_into().ok())
        .collect();
    embedding_in_cells(cells, &boundary, x, points, slack)
}

/// [`embedding`] from the type-n cells and the boundary quads alone (as
/// [`refined_cells`](crate::lattice::refined_cells) gives them), without
/// the level's full topology.
pub fn embedding_in_cells(
    cells: &TypeNCells,
    boundary_quads: &[[u32; 4]],
    x: &[Point3],
    points: &[Point3],
    slack: Real,
) -> Embedding {
    let margin = 1e-9 * bbox_diagonal(x);
    let boundary: HashSet<[u32; 4]> = boundary_quads
        .iter()
        .map(|q| {
            let mut q = *q;
            q.sort_unstable();
            q
        })
        .collect();
    let on_boundary = |q: &Option<[u32; 4]>| {
        q.is_some_and(|mut q| {
            q.sort_unstable();
            boundary.contains(&q)
        })
    };
    let index = CellIndex::new(cells, x, margin);
    let found: Vec<Option<(u32, CellCoords, bool)>> = points
        .par_iter()
        .map(|p| {
            let mut best: Option<(u32, CellCoords)> = None;
            for &c in index.candidates(p) {
                if !index.box_contains(c, p) {
                    continue;
                }
                let Some(cc) = cell_coords(cells, c as usize, x, p) else {
                    continue;
                };
                if cc.outside_by <= 1e-9 {
                    return Some((c, cc, false));
                }
                if !on_boundary(&cc.exit_face)
                    && best.as_ref().is_none_or(|b| cc.outside_by < b.1.outside_by)
                {
                    best = Some((c, cc));
                }
            }
            best.filter(|b| b.1.outside_by <= slack)
                .map(|(c, cc)| (c, cc, true))
        })
        .collect();
    let mut cell = Vec::with_capacity(points.len());
    let mut outside = Vec::new();
    let (mut snapped, mut max_it, mut type_n) = (0, 0, 0);
    let weights = StencilTable::from_row_fn(points.len(), x.len(), |r, b| {
        if let Some((_, cc, _)) = &found[r] {
            for &(v, w) in &cc.weights {
                b.add(v, w);
            }
        }
    });
    for (i, f) in found.iter().enumerate() {
        match f {
            Some((c, cc, snap)) => {
                cell.push(*c);
                snapped += *snap as usize;
                max_it = max_it.max(cc.iterations);
                type_n += (cells.valence(*c as usize) != 3) as usize;
            }
            None => {
                cell.push(u32::MAX);
                outside.push(i as u32);
            }
        }
    }
    Embedding {
        weights,
        cell,
        outside,
        snapped,
        max_newton_iterations: max_it,
        in_type_n_cells: type_n,
    }
}

//! Automatic lattices around a model (multiresolution-lattice FFD paper):
//! the lowest level as an axis-aligned or oriented (PCA) bounding box, octree
//! refinement of the box, and culling of cells that hold no model vertex.
//!
//! On a box, the octree rules (cell, face and edge points as averages of the
//! cell's, face's and edge's vertices) produce the regular `2^K` subdivision
//! exactly, so level `K` is built directly as that grid.

use nalgebra::{Matrix3, SymmetricEigen};

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};

use super::builders::hexahedra;
use super::lattice::Lattice;

/// How the lowest-level box is oriented.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoxKind {
    /// Axis-aligned bounding box (default).
    #[default]
    Aabb,
    /// Oriented bounding box along the principal axes of the vertices (PCA).
    Obb,
}

/// Parameters of [`box_lattice`].
#[derive(Clone, Debug)]
pub struct BoxLatticeParams {
    /// Box orientation (default [`BoxKind::Aabb`]).
    pub kind: BoxKind,
    /// Margin added on every side, as a fraction of the model's diagonal (default 0.05).
    pub margin: Real,
    /// Octree levels `K`: the box is split into `2^K` cells per axis (default 0, one cell; at most 7).
    pub octree_levels: usize,
    /// Drop cells holding no model vertex (default true; only when `K > 0`).
    pub cull: bool,
    /// Cells kept around every occupied cell, in cells (default 1): keeps the
    /// lattice face-connected and the vertices away from its staircase
    /// boundary, where Catmull-Clark boundary rules pull the region inwards.
    pub dilate: usize,
}

impl Default for BoxLatticeParams {
    fn default() -> Self {
        BoxLatticeParams {
            kind: BoxKind::Aabb,
            margin: 0.05,
            octree_levels: 0,
            cull: true,
            dilate: 1,
        }
    }
}

/// Origin and three edge vectors of the bounding box of `points` in the frame
/// chosen by `kind`, grown by `margin · diagonal` on every side.
pub fn bounding_frame(
    points: &[Point3],
    kind: BoxKind,
    margin: Real,
) -> Result<(Point3, [Vector3; 3])> {
    if points.is_empty() {
        return Err(Error::input("no vertices to build a lattice around"));
    }
    if let Some(i) = points
        .iter()
        .position(|p| !p.coords.iter().all(|x| x.is_finite()))
    {
        return Err(Error::input(format!(
            "vertex {i}: coordinate is not a finite number"
        )));
    }
    let axes = match kind {
        BoxKind::Aabb => Matrix3::identity(),
        BoxKind::Obb => {
            let n = points.len() as Real;
            let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
            let cov = points.iter().fold(Matrix3::zeros(), |s, p| {
                let d = p.coords - mean;
                s + d * d.transpose()
            }) / n;
            let mut e = SymmetricEigen::new(cov).eigenvectors;
            if e.determinant() < 0.0 {
                e.set_column(2, &(-e.column(2)));
            }
            e
        }
    };
    let d = bbox_diagonal(points);
    let pad = margin * d.max(Real::MIN_POSITIVE);
    let mut lo = Vector3::repeat(Real::MAX);
    let mut hi = Vector3::repeat(Real::MIN);
    for p in points {
        let q = axes.transpose() * p.coords;
        lo = lo.inf(&q);
        hi = hi.sup(&q);
    }
    // Flat or degenerate models still get a box of positive thickness.
    let min_thick = 1e-3 * d.max(1e-12);
    for k in 0..3 {
        lo[k] -= pad;
        hi[k] += pad;
        if hi[k] - lo[k] < min_thick {
            let c = 0.5 * (lo[k] + hi[k]);
            lo[k] = c - 0.5 * min_thick;
            hi[k] = c + 0.5 * min_thick;
        }
    }
    let origin = Point3::from(axes * lo);
    let ext = hi - lo;
    Ok((origin, [0, 1, 2].map(|k| axes.column(k) * ext[k])))
}

/// The kept cells of the box grid around some points (before any vertex is
/// moved): the box frame, the cells per axis and one flag per cell.
pub(super) struct BoxCells {
    /// Corner of the box.
    pub origin: Point3,
    /// The three edge vectors of the box.
    pub axes: [Vector3; 3],
    /// Cells per axis (`2^K`).
    pub n: usize,
    /// `keep[i + n (j + n k)]`: cell `(i, j, k)` is in the lattice.
    pub keep: Vec<bool>,
}

impl BoxCells {
    /// Index of cell `(i, j, k)`.
    pub fn cell_id(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.n * (j + self.n * k)
    }

    /// Grid coordinates of `p` (`[0, n]` per axis inside the box).
    pub fn grid_coords(&self, p: &Point3) -> Option<Vector3> {
        let inv = Matrix3::from_columns(&self.axes).try_inverse()?;
        Some(inv * (p - self.origin) * self.n as Real)
    }

    /// Position of grid vertex `(i, j, k)`, with fractional grid coordinates allowed.
    pub fn position(&self, t: Vector3) -> Point3 {
        let t = t / self.n as Real;
        self.origin + self.axes[0] * t.x + self.axes[1] * t.y + self.axes[2] * t.z
    }

    /// The eight grid vertices of cell `(i, j, k)` in VTK order.
    pub fn corners(i: usize, j: usize, k: usize) -> [(usize, usize, usize); 8] {
        [
            (i, j, k),
            (i + 1, j, k),
            (i + 1, j + 1, k),
            (i, j + 1, k),
            (i, j, k + 1),
            (i + 1, j, k + 1),
            (i + 1, j + 1, k + 1),
            (i, j + 1, k + 1),
        ]
    }
}

/// The box, its `2^K` grid and the cells kept after culling and dilation.
pub(super) fn box_cells(points: &[Point3], params: &BoxLatticeParams) -> Result<BoxCells> {
    if params.octree_levels > 7 {
        return Err(Error::input(format!(
            "{} octree levels requested; at most 7 (128³ cells) are allowed",
            params.octree_levels
        )));
    }
    if !(params.margin.is_finite() && params.margin >= 0.0) {
        return Err(Error::input(format!(
            "margin {} must be a finite number ≥ 0",
            params.margin
        )));
    }
    let (origin, axes) = bounding_frame(points, params.kind, params.margin)?;
    let n = 1usize << params.octree_levels;
    let mut cells = BoxCells {
        origin,
        axes,
        n,
        keep: vec![!(params.cull && n > 1); n * n * n],
    };
    if params.cull && n > 1 {
        let mut occupied = vec![false; n * n * n];
        for p in points {
            let t = cells
                .grid_coords(p)
                .ok_or_else(|| Error::input("the bounding box is degenerate"))?;
            let ijk = [0, 1, 2].map(|k| (t[k].floor().max(0.0) as usize).min(n - 1));
            occupied[cells.cell_id(ijk[0], ijk[1], ijk[2])] = true;
        }
        let r = params.dilate as i64;
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    if !occupied[cells.cell_id(i, j, k)] {
                        continue;
                    }
                    for dk in -r..=r {
                        for dj in -r..=r {
                            for di in -r..=r {
                                let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                                let inside = |x: i64| (0..n as i64).contains(&x);
                                if inside(a) && inside(b) && inside(c) {
                                    let id = cells.cell_id(a as usize, b as usize, c as usize);
                                    cells.keep[id] = true;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(cells)
}

/// The kept cells as hexahedra: grid-vertex positions from `position`, and
/// the new index of every used grid vertex (`u32::MAX` when unused).
pub(super) fn kept_hexahedra(
    cells: &BoxCells,
    mut position: impl FnMut(usize, usize, usize) -> Point3,
) -> (Vec<Point3>, Vec<[u32; 8]>, Vec<u32>) {
    let n = cells.n;
    let vid = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let mut new_id = vec![u32::MAX; (n + 1) * (n + 1) * (n + 1)];
    let mut positions = Vec::new();
    let mut hexes = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                if !cells.keep[cells.cell_id(i, j, k)] {
                    continue;
                }
                let h = BoxCells::corners(i, j, k).map(|(a, b, c)| {
                    let v = vid(a, b, c);
                    if new_id[v] == u32::MAX {
                        new_id[v] = positions.len() as u32;
                        positions.push(position(a, b, c));
                    }
                    new_id[v]
                });
                hexes.push(h);
            }
        }
    }
    (positions, hexes, new_id)
}

/// A lattice around `points`: the bounding box split into `2^K` cells per
/// axis, empty cells culled (then dilated), as a hexahedral lattice.
pub fn box_lattice(points: &[Point3], params: &BoxLatticeParams) -> Result<Lattice> {
    let cells = box_cells(points, params)?;
    let (positions, hexes, _) = kept_hexahedra(&cells, |a, b, c| {
        cells.position(Vector3::new(a as Real, b as Real, c as Real))
    });
    hexahedra(positions, &hexes)
}

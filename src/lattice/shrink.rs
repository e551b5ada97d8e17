//! Shrink octree lattices (multiresolution-lattice FFD paper, §2.2): "the
//! control points on the boundary of each axis are moved close to the model
//! along the axis while maintaining a certain offset".
//!
//! The paper gives no formula; ours, in the box's grid coordinates (one
//! unit per cell): a control point faces `+a` along axis `a` when it has
//! lattice cells only on its `−a` side along that axis (and `−a`
//! symmetrically). Such a point moves along `a` only, inwards, to the
//! farthest model vertex in the slab it controls (the other two grid
//! coordinates within one cell of its own, and along `a` from where its grid
//! line enters the lattice) plus the offset. It never moves outwards and
//! never more than three quarters of a cell, so the cells behind it keep
//! their orientation; a cell whose trilinear Jacobian would fall below a
//! tenth of its rest value at a corner gets its moves halved until it does
//! not (reported).

use nalgebra::Matrix3;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};

use super::box_lattice::{BoxCells, BoxLatticeParams, box_cells, kept_hexahedra};
use super::builders::hexahedra;
use super::lattice::Lattice;
use super::topology::Csr;

/// Largest move of a control point, in cells.
const MAX_MOVE: Real = 0.75;

/// What [`shrunk_box_lattice`] did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ShrinkReport {
    /// Control points moved.
    pub moved: usize,
    /// Largest move, as a fraction of the model's diagonal.
    pub max_move: Real,
    /// Cells whose moves were halved to keep them from folding.
    pub limited_cells: usize,
}

/// The automatic lattice of [`box_lattice`](super::box_lattice) with its
/// boundary control points moved towards the model, keeping `offset` (a
/// fraction of the model's bounding-box diagonal) between them and the
/// farthest model vertex they control. With `octree_levels = 0` this is the
/// model's bounding box grown by `offset` on every side.
pub fn shrunk_box_lattice(
    points: &[Point3],
    params: &BoxLatticeParams,
    offset: Real,
) -> Result<(Lattice, ShrinkReport)> {
    if !(offset.is_finite() && offset >= 0.0) {
        return Err(Error::input(format!(
            "shrink offset {offset} must be a finite number ≥ 0"
        )));
    }
    let cells = box_cells(points, params)?;
    let n = cells.n;
    let diag = bbox_diagonal(points);
    let lengths = cells.axes.map(|a| a.norm() / n as Real);
    let grid: Vec<Vector3> = points
        .iter()
        .map(|p| cells.grid_coords(p))
        .collect::<Option<_>>()
        .ok_or_else(|| Error::input("the bounding box is degenerate"))?;
    // Model vertices by grid cell (clamped into the grid).
    let by_cell = Csr::from_pairs(
        n * n * n,
        grid.iter().enumerate().map(|(q, t)| {
            let c = [0, 1, 2].map(|k| (t[k].floor().max(0.0) as usize).min(n - 1));
            (cells.cell_id(c[0], c[1], c[2]) as u32, q as u32)
        }),
    );
    let vid = |v: [usize; 3]| v[0] + (n + 1) * (v[1] + (n + 1) * v[2]);
    // Cell at grid vertex v offset by d ∈ {-1, 0}³, if kept.
    let kept = |v: [usize; 3], d: [i64; 3]| {
        let c = [0, 1, 2].map(|k| v[k] as i64 + d[k]);
        c.iter().all(|&x| (0..n as i64).contains(&x))
            && cells.keep[cells.cell_id(c[0] as usize, c[1] as usize, c[2] as usize)]
    };
    let present =
        |v: [usize; 3]| (0..8).any(|m| kept(v, [0, 1, 2].map(|k| -(((m >> k) & 1) as i64))));
    // Which side of v along axis a holds cells: (below, above).
    let sides = |v: [usize; 3], a: usize| {
        let mut below = false;
        let mut above = false;
        for m in 0..4 {
            let mut d = [0i64; 3];
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            d[b] = -((m & 1) as i64);
            d[c] = -(((m >> 1) & 1) as i64);
            let mut lo = d;
            lo[a] = -1;
            below |= kept(v, lo);
            above |= kept(v, d);
        }
        (below, above)
    };
    // Grid-coordinate moves of every grid vertex.
    let mut moves = vec![Vector3::zeros(); (n + 1).pow(3)];
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let v = [i, j, k];
                if !present(v) {
                    continue;
                }
                for a in 0..3 {
                    let (below, above) = sides(v, a);
                    if below == above {
                        continue;
                    }
                    let s: i64 = if below { 1 } else { -1 };
                    // Where the grid line enters the lattice behind v.
                    let mut w = v;
                    loop {
                        let next = w[a] as i64 - s;
                        if !(0..=n as i64).contains(&next) {
                            break;
                        }
                        let mut u = w;
                        u[a] = next as usize;
                        if !present(u) {
                            break;
                        }
                        w = u;
                    }
                    let (from, to) = if s > 0 {
                        (w[a] as Real, v[a] as Real)
                    } else {
                        (v[a] as Real, w[a] as Real)
                    };
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    let mut far = Real::NEG_INFINITY;
                    let span = |x: usize| x.saturating_sub(1)..(x + 2).min(n);
                    let mut cell = [0usize; 3];
                    for ca in (from as usize)..(to as usize).max(from as usize + 1).min(n) {
                        cell[a] = ca;
                        for cb in span(v[b]) {
                            cell[b] = cb;
                            for cc in span(v[c]) {
                                cell[c] = cc;
                                let id = cells.cell_id(cell[0], cell[1], cell[2]);
                                for &q in by_cell.row(id) {
                                    let t = &grid[q as usize];
                                    if (t[b] - v[b] as Real).abs() <= 1.0
                                        && (t[c] - v[c] as Real).abs() <= 1.0
                                        && t[a] >= from
                                        && t[a] <= to
                                    {
                                        far = far.max(s as Real * t[a]);
                                    }
                                }
                            }
                        }
                    }
                    if far == Real::NEG_INFINITY {
                        continue;
                    }
                    let target = far + offset * diag / lengths[a];
                    let inward = (s as Real * v[a] as Real - target).clamp(0.0, MAX_MOVE);
                    moves[vid(v)][a] = -(s as Real) * inward;
                }
            }
        }
    }
    // Keep every kept cell unfolded: halve its corners' moves until the
    // trilinear Jacobian at each corner is at least a tenth of the rest one.
    let mut limited_cells = 0;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                if !cells.keep[cells.cell_id(i, j, k)] {
                    continue;
                }
                let corners = BoxCells::corners(i, j, k).map(|(a, b, c)| vid([a, b, c]));
                let mut halved = false;
                for _ in 0..20 {
                    if corners_unfolded(&corners.map(|c| moves[c])) {
                        break;
                    }
                    halved = true;
                    for &c in &corners {
                        moves[c] *= 0.5;
                    }
                }
                limited_cells += halved as usize;
            }
        }
    }
    let (positions, hexes, new_id) = kept_hexahedra(&cells, |a, b, c| {
        let t = Vector3::new(a as Real, b as Real, c as Real) + moves[vid([a, b, c])];
        cells.position(t)
    });
    let mut report = ShrinkReport {
        limited_cells,
        ..Default::default()
    };
    for (g, &id) in new_id.iter().enumerate() {
        if id == u32::MAX || moves[g] == Vector3::zeros() {
            continue;
        }
        report.moved += 1;
        let d = (0..3)
            .map(|a| (moves[g][a] * lengths[a]).abs())
            .fold(0.0, Real::max);
        report.max_move = report.max_move.max(d / diag.max(Real::MIN_POSITIVE));
    }
    Ok((hexahedra(positions, &hexes)?, report))
}

/// True when the unit cube with its corners (VTK order) displaced by `d`
/// keeps a trilinear Jacobian of at least 0.1 at all eight corners (in grid
/// units, where the rest Jacobian is 1).
fn corners_unfolded(d: &[Vector3; 8]) -> bool {
    let x = BoxCells::corners(0, 0, 0)
        .map(|(a, b, c)| Vector3::new(a as Real, b as Real, c as Real))
        .iter()
        .zip(d)
        .map(|(p, q)| p + q)
        .collect::<Vec<_>>();
    // VTK corner index of (i, j, k) ∈ {0, 1}³.
    let at = |i: usize, j: usize, k: usize| [0, 1, 3, 2][i + 2 * j] + 4 * k;
    (0..8).all(|m| {
        let (i, j, k) = (m & 1, (m >> 1) & 1, (m >> 2) & 1);
        let ex = x[at(1, j, k)] - x[at(0, j, k)];
        let ey = x[at(i, 1, k)] - x[at(i, 0, k)];
        let ez = x[at(i, j, 1)] - x[at(i, j, 0)];
        Matrix3::from_columns(&[ex, ey, ez]).determinant() >= 0.1
    })
}

//! Evaluating a [`PatchTable`] at its current positions: a 16-point
//! bicubic product on regular patches and quadtree leaves, exact local
//! evaluation in the innermost cells at irregular vertices.

use super::{BicubicPiece, CHAIN_COLUMNS, LeafPoints, PatchPoint, PatchTable, TREE_DEPTH};
use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use crate::limit::LimitPoint;
use crate::limit::bspline::cubic_basis;
use crate::limit::local_eval::{CornerChain, evaluate_local};
use crate::limit::param::{CORNERS, chain};

impl PatchTable {
    /// Evaluates patch `f` at `(s, t) ∈ [0, 1]²`.
    pub fn eval(&self, f: usize, st: [Real; 2]) -> Result<PatchPoint> {
        if let Some((grid, x, jac)) = self.bicubic_piece(f, st) {
            let e = bicubic(grid, x);
            return Ok(PatchPoint {
                p: e.p,
                d: jac.map_or(e.d, |j| chain(e.d, j)),
            });
        }
        let patch = &self.patches[f];
        // The innermost cell at the irregular vertex: exact evaluation from
        // the cell's local patch (its weights are over the tree's columns,
        // in order), followed towards the vertex once per positions when
        // its ring is large. Exactly at a corner the evaluator's corner
        // tangents (which depend on the depth they are taken at) are kept.
        if let Some(tree) = patch.tree.get()
            && let Some((i, leaf, cell, x)) = tree.cell_at(st)
            && !CORNERS.contains(&x)
        {
            let q: [Vector3; 6] = if tree.cols.len() > CHAIN_COLUMNS
                && let LeafPoints::Cell(corner) = tree.points[i].get_or_init(|| {
                    let cell = cell.applied(|l| self.level_positions[tree.cols[l] as usize].coords);
                    LeafPoints::Cell(Box::new(CornerChain::new(cell, TREE_DEPTH)))
                }) {
                let s = corner.evaluate(x);
                std::array::from_fn(|k| Vector3::from_column_slice(&s.weights[k]))
            } else {
                let s = evaluate_local(cell.clone(), x, [[1.0, 0.0], [0.0, 1.0]], TREE_DEPTH);
                std::array::from_fn(|k| {
                    s.weights[k]
                        .iter()
                        .zip(&tree.cols)
                        .map(|(&w, &c)| w * self.level_positions[c as usize].coords)
                        .sum()
                })
            };
            return Ok(PatchPoint {
                p: Point3::from(q[0]),
                d: chain([q[1], q[2], q[3], q[4], q[5]], leaf.jac),
            });
        }
        let s = self.sample(f, st);
        let e = self
            .evaluator
            .evaluate(s.face as usize, s.u, s.v, &self.positions)?;
        Ok(PatchPoint {
            p: e.p,
            d: chain([e.du, e.dv, e.duu, e.duv, e.dvv], patch.axes),
        })
    }

    /// Limit position and derivatives at base sample `(face, u, v)`.
    pub fn evaluate(&self, face: usize, u: Real, v: Real) -> Result<LimitPoint> {
        if face + 1 >= self.offsets[0].len() {
            return Err(Error::out_of_range(format!("face {face} out of range")));
        }
        let (f, st) = self.locate(face, u, v);
        let e = self.eval(f, st)?;
        // (s, t) = A⁻¹ ((u, v) − o): invert the patch axes for the chain rule.
        let a = self.patches[f].axes;
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let d = chain(e.d, inv);
        Ok(LimitPoint {
            p: e.p,
            du: d[0],
            dv: d[1],
            duu: d[2],
            duv: d[3],
            dvv: d[4],
        })
    }

    /// The limit point of patch `f` at `(s, t)`: [`eval`](Self::eval)'s
    /// position without the derivatives (a quarter of the work on a
    /// bicubic piece).
    pub fn position(&self, f: usize, st: [Real; 2]) -> Result<Point3> {
        match self.bicubic_piece(f, st) {
            Some((grid, x, _)) => {
                let (bs, bt) = (cubic_basis(x[0])[0], cubic_basis(x[1])[0]);
                let mut p = [0.0; 3];
                for (row, ws) in grid.chunks_exact(4).zip(bs) {
                    for (x, p) in p.iter_mut().enumerate() {
                        *p += ws
                            * (bt[0] * row[0][x]
                                + bt[1] * row[1][x]
                                + bt[2] * row[2][x]
                                + bt[3] * row[3][x]);
                    }
                }
                Ok(Point3::from(p))
            }
            None => Ok(self.eval(f, st)?.p),
        }
    }

    /// The bicubic piece of patch `f` holding `(s, t)`: its 16 control points,
    /// the point in its own parameters and, for a quadtree leaf, the
    /// Jacobian of those; `None` in the innermost cell at an irregular
    /// vertex.
    fn bicubic_piece(&self, f: usize, st: [Real; 2]) -> Option<BicubicPiece<'_>> {
        let patch = &self.patches[f];
        if patch.regular {
            let grid: &[Point3; 16] = self.grid_points[16 * f..16 * f + 16]
                .try_into()
                .expect("16 control points per patch");
            return Some((grid, st, None));
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        let (i, leaf, rows, x) = tree.leaf_at(st)?;
        let cols = &tree.cols;
        let nc = cols.len().max(1);
        let points = tree.points[i].get_or_init(|| {
            LeafPoints::Grid(Box::new(std::array::from_fn(|k| {
                let mut p = [0.0; 3];
                for (&w, &c) in rows[k * nc..(k + 1) * nc].iter().zip(cols) {
                    let q = &self.level_positions[c as usize];
                    p[0] += w * q.x;
                    p[1] += w * q.y;
                    p[2] += w * q.z;
                }
                Point3::from(p)
            })))
        });
        let LeafPoints::Grid(grid) = points else {
            return None;
        };
        Some((grid, x, Some(leaf.jac)))
    }
}

/// Bicubic B-spline patch value and derivatives at `(s, t)`.
fn bicubic(grid: &[Point3; 16], st: [Real; 2]) -> PatchPoint {
    // The weights of `patch_weights`, as a tensor product: first along `t`
    // (`c[k][a]`, derivative order `k` in `t`), then along `s`. Written out
    // on plain coordinates: this is the inner loop of every closest-point
    // descent.
    let (bs, bt) = (cubic_basis(st[0]), cubic_basis(st[1]));
    let mut c = [[[0.0; 3]; 4]; 3];
    for (a, row) in grid.chunks_exact(4).enumerate() {
        for (k, w) in bt.iter().enumerate() {
            for x in 0..3 {
                c[k][a][x] =
                    w[0] * row[0][x] + w[1] * row[1][x] + w[2] * row[2][x] + w[3] * row[3][x];
            }
        }
    }
    let along = |ds: usize, dt: usize| -> Vector3 {
        let (w, c) = (&bs[ds], &c[dt]);
        Vector3::from_fn(|x, _| w[0] * c[0][x] + w[1] * c[1][x] + w[2] * c[2][x] + w[3] * c[3][x])
    };
    PatchPoint {
        p: Point3::from(along(0, 0)),
        d: [
            along(1, 0),
            along(0, 1),
            along(2, 0),
            along(1, 1),
            along(0, 2),
        ],
    }
}

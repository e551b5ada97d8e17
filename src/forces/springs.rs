//! Data springs and the point-drag spring, treated implicitly.
//!
//! A spring of stiffness `k` from data point `d` to the surface point
//! `x = J(u, v) p` has energy `½ k |J p − d|²`; its force on the control
//! points is `Jᵀ k (d − J p)` (Qin et al. 1998, eq. 15). Summed over the
//! springs, the stiffness `Σ k JᵀJ` and the load `Σ k Jᵀ d` enter the implicit
//! step directly, which is unconditionally stable where an explicit force is
//! not. The rows `J` come from the closest points of a
//! [`ClosestPointEngine`] (over its level-`L` vertices) and are carried to the
//! control points through `P_L = S P_0`.

use crate::error::{Error, Result};
use crate::limit::{ClosestPoint, ClosestPointEngine};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;
use rayon::prelude::*;

/// The implicit spring terms over the control points.
#[derive(Clone, Debug)]
pub struct SpringSystem {
    /// `Σ k JᵀJ` (`n × n`).
    pub matrix: StencilTable,
    /// `Σ k Jᵀ d` (`n`).
    pub rhs: Vec<Point3>,
    /// `½ Σ k |x − d|²` at the current surface.
    pub energy: Real,
}

impl SpringSystem {
    /// Adds another spring system over the same control points (matrices,
    /// loads and energies add).
    /// Matrices with the same pattern (as [`PatchAssembly`](super::PatchAssembly)
    /// makes them) add entry by entry.
    pub fn add(&mut self, other: &SpringSystem) -> Result<()> {
        let (a, b) = (&self.matrix, &other.matrix);
        if a.num_cols == b.num_cols && a.offsets == b.offsets && a.indices == b.indices {
            for (x, y) in self.matrix.weights.iter_mut().zip(&b.weights) {
                *x += y;
            }
        } else {
            self.matrix = self.matrix.linear_combination(1.0, &other.matrix, 1.0)?;
        }
        if self.rhs.len() != other.rhs.len() {
            return Err(Error::input(format!(
                "springs over {} and {} control points",
                self.rhs.len(),
                other.rhs.len()
            )));
        }
        for (r, o) in self.rhs.iter_mut().zip(&other.rhs) {
            r.coords += o.coords;
        }
        self.energy += other.energy;
        Ok(())
    }
}

/// Springs from `points[i]` to `closest[i]` with stiffness `k[i]` (springs
/// with `k = 0` are skipped).
pub fn spring_system(
    engine: &ClosestPointEngine,
    points: &[Point3],
    closest: &[ClosestPoint],
    k: &[Real],
) -> Result<SpringSystem> {
    if points.len() != closest.len() || points.len() != k.len() {
        return Err(Error::input(format!(
            "springs: {} points, {} closest points, {} stiffnesses",
            points.len(),
            closest.len(),
            k.len()
        )));
    }
    if let Some(i) = k.iter().position(|&k| !(k >= 0.0 && k.is_finite())) {
        return Err(Error::input(format!("spring {i} has stiffness {}", k[i])));
    }
    let table = engine.table();
    let s = table.to_level();
    let stencils: Vec<(Vec<u32>, Vec<Real>)> = closest
        .par_iter()
        .map(|c| table.position_stencil(c.patch.0 as usize, c.patch.1))
        .collect();
    let mut rows = StencilTable::with_capacity(s.num_rows(), points.len(), 16 * points.len());
    for (cols, w) in stencils {
        rows.push_row(cols.into_iter().zip(w));
    }
    let surface: Vec<Point3> = closest.iter().map(|c| c.point).collect();
    row_springs(&rows.compose(s)?, &surface, points, k)
}

/// Springs from surface points `x_i = J_i p` (rows `j` over the control
/// points, `x` their current positions) to targets `d_i` with stiffness `k_i`.
pub fn row_springs(
    j: &StencilTable,
    x: &[Point3],
    d: &[Point3],
    k: &[Real],
) -> Result<SpringSystem> {
    if j.num_rows() != d.len() || x.len() != d.len() || k.len() != d.len() {
        return Err(Error::input(format!(
            "springs: {} rows, {} surface points, {} targets, {} stiffnesses",
            j.num_rows(),
            x.len(),
            d.len(),
            k.len()
        )));
    }
    let sk: Vec<Real> = k.iter().map(|k| k.sqrt()).collect();
    let b = j.scale_rows(&sk)?;
    let loads: Vec<Point3> = d
        .iter()
        .zip(&sk)
        .map(|(d, &s)| Point3::from(s * d.coords))
        .collect();
    let energy = x
        .iter()
        .zip(d)
        .zip(k)
        .map(|((x, d), k)| 0.5 * k * (x - d).norm_squared())
        .sum();
    Ok(SpringSystem {
        matrix: b.gram(),
        rhs: b.apply_transpose(&loads)?,
        energy,
    })
}

/// User-placed points as springs spread over the surface: point `d_i`,
/// whose closest surface point is `c_i`, pulls every surface sample `x_s`
/// (rows `j` over the control points, current positions `x`) within
/// `radius` of `c_i` towards `x_s + (d_i − c_i)`, with stiffness
/// `k_i w_s`, `w_s ∝ (1 − r_s²/radius²)²` (Wendland's compact kernel of the
/// sample's distance `r_s` to `c_i`), normalised to sum 1; with no sample
/// in range the nearest one takes it all. The total pull and the energy
/// `½ k_i |d_i − c_i|²` are those of one spring at `c_i` (Qin, Mandal,
/// Vemuri 1998, eq. 15), but the force no longer concentrates on the few
/// control points under `c_i` as the mesh is refined, which raises a spike:
/// it acts on a patch of the surface as wide as `radius` at every level.
pub fn spread_point_springs(
    j: &StencilTable,
    x: &[Point3],
    points: &[Point3],
    closest: &[ClosestPoint],
    k: &[Real],
    radius: Real,
) -> Result<SpringSystem> {
    if points.len() != closest.len() || points.len() != k.len() || j.num_rows() != x.len() {
        return Err(Error::input(format!(
            "spread springs: {} points, {} closest points, {} stiffnesses; {} rows, {} samples",
            points.len(),
            closest.len(),
            k.len(),
            j.num_rows(),
            x.len()
        )));
    }
    if !(radius > 0.0 && radius.is_finite()) || x.is_empty() {
        return Err(Error::input(format!(
            "spread springs need samples and a positive radius (got {radius}, {} samples)",
            x.len()
        )));
    }
    let per_point: Vec<Vec<(usize, Point3, Real)>> = points
        .par_iter()
        .zip(closest)
        .zip(k)
        .map(|((d, c), &k)| {
            let shift = d - c.point;
            let mut near: Vec<(usize, Real)> = x
                .iter()
                .enumerate()
                .filter_map(|(s, xs)| {
                    let q = (xs - c.point).norm_squared() / (radius * radius);
                    (q < 1.0).then_some((s, (1.0 - q) * (1.0 - q)))
                })
                .collect();
            if near.is_empty() {
                let nearest = (0..x.len())
                    .min_by(|&a, &b| {
                        (x[a] - c.point)
                            .norm_squared()
                            .total_cmp(&(x[b] - c.point).norm_squared())
                    })
                    .unwrap_or(0);
                near.push((nearest, 1.0));
            }
            let total: Real = near.iter().map(|n| n.1).sum();
            near.into_iter()
                .map(|(s, w)| (s, x[s] + shift, k * w / total))
                .collect()
        })
        .collect();
    let all: Vec<(usize, Point3, Real)> = per_point.into_iter().flatten().collect();
    let rows: Vec<usize> = all.iter().map(|a| a.0).collect();
    let xs: Vec<Point3> = rows.iter().map(|&s| x[s]).collect();
    let targets: Vec<Point3> = all.iter().map(|a| a.1).collect();
    let ks: Vec<Real> = all.iter().map(|a| a.2).collect();
    row_springs(&j.select_rows(&rows), &xs, &targets, &ks)
}

/// A single point-drag spring of stiffness `k` pulling the surface point
/// `at` (a closest point of `engine`) towards `target`: the interactive drag
/// of Qin et al. 1998 (§5.2), as an implicit term.
pub fn drag_spring(
    engine: &ClosestPointEngine,
    at: &ClosestPoint,
    target: Point3,
    k: Real,
) -> Result<SpringSystem> {
    spring_system(engine, &[target], std::slice::from_ref(at), &[k])
}

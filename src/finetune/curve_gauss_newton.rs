//! Energy (13) of closed-curve fine tuning as a sum of squares in point
//! coordinates, for the Levenberg-Marquardt solver.
//!
//! The gauge is the one of `curve_frames` (the fixed point `C_f` stays, the
//! leg after it keeps its direction `u`, in 3-D the plane leg stays in
//! `span(u, w)`), written with displacement variables `z` (zero at the
//! start): a point reached by a free leg moves freely
//! (`C = C⁰ + Σ z_k e_k`), a point reached by a constrained leg moves with
//! its predecessor plus the leg's allowed directions
//! (`C_{t+1} = C⁰_{t+1} + ΔC_t + Σ z_k a_k`). Every residual then involves
//! at most three consecutive points, so the Gauss-Newton matrix is sparse
//! (a cycle of small blocks), unlike in leg coordinates, where the closing
//! leg couples all variables.
//!
//! Residuals: `√k_l (l_i − l_i^opt)` per leg with `∂/∂C_{i+1} = √k_l L̂_i`,
//! and `√k_a wrap(θ_i − θ_i^opt)` per joint with the angle gradients of
//! `curve_energy`, so that `Σ r² = E` of eq. 13; for a 3-D curve each joint
//! also gets the zero-valued curvature rows of `angle_curvature`.

use crate::linalg::{LeastSquares, Residuals};
use crate::math::{Point3, Real, Vector3};

use super::angle_curvature::transverse_rows;
use super::curve_energy::{SpringTargets, joint_angle, joint_angle_gradients, wrap_angle};
use super::curve_solver::SpringProblem;

/// Energy (13) over point displacements, with the gauge of a [`SpringProblem`].
#[derive(Clone, Debug)]
pub struct CurvePointProblem<'a> {
    legs: &'a SpringProblem,
    start: Vec<Point3>,
    /// Per control point: the variables moving it and their directions.
    moves: Vec<Vec<(usize, Vector3)>>,
    /// The point each variable belongs to.
    nodes: Vec<usize>,
}

impl<'a> CurvePointProblem<'a> {
    /// The point form of `legs` at the variables `x` of `legs`.
    pub fn new(legs: &'a SpringProblem, x: &[Real]) -> Self {
        let start = legs.points(x);
        let n = start.len();
        let free_axes = if legs.targets.planar { 2 } else { 3 };
        let mut moves: Vec<Vec<(usize, Vector3)>> = vec![Vec::new(); n];
        let mut nodes = Vec::new();
        for (t, leg) in legs.legs.iter().enumerate() {
            let (prev, here) = ((legs.fixed + t) % n, (legs.fixed + t + 1) % n);
            let mut m = if t > 0 && leg.axes.len() < free_axes {
                moves[prev].clone()
            } else {
                Vec::new()
            };
            for (_, a) in &leg.axes {
                m.push((nodes.len(), *a));
                nodes.push(here);
            }
            moves[here] = m;
        }
        CurvePointProblem {
            legs,
            start,
            moves,
            nodes,
        }
    }

    /// The control points at displacement variables `z`.
    pub fn points(&self, z: &[Real]) -> Vec<Point3> {
        self.start
            .iter()
            .zip(&self.moves)
            .map(|(p, m)| m.iter().fold(*p, |p, (v, a)| p + z[*v] * a))
            .collect()
    }

    fn targets(&self) -> &SpringTargets {
        &self.legs.targets
    }

    /// Appends residual `r` with point gradients `(point, ∂r/∂C)`.
    fn push(&self, out: &mut Residuals, r: Real, grads: &[(usize, Vector3)]) {
        out.push(
            r,
            grads
                .iter()
                .flat_map(|(p, gp)| self.moves[*p].iter().map(move |(v, a)| (*v, gp.dot(a)))),
        );
    }
}

impl LeastSquares for CurvePointProblem<'_> {
    fn num_vars(&self) -> usize {
        self.nodes.len()
    }

    fn nodes(&self) -> Vec<usize> {
        self.nodes.clone()
    }

    fn energy(&self, z: &[Real]) -> Real {
        self.targets().energy(&self.points(z), None)
    }

    fn residuals(&self, z: &[Real], out: &mut Residuals) {
        out.clear();
        let c = self.points(z);
        let m = c.len();
        let t = self.targets();
        let (sl, sa) = (t.k_length.sqrt(), t.k_angle.sqrt());
        let leg = |i: usize| c[(i + 1) % m] - c[i];
        for i in 0..m {
            let b = leg(i);
            let lb = b.norm();
            let u = if lb > 0.0 { b / lb } else { Vector3::zeros() };
            let (next, prev) = ((i + 1) % m, (i + m - 1) % m);
            self.push(
                out,
                sl * (lb - t.lengths[i]),
                &[(next, sl * u), (i, -sl * u)],
            );
            let a = leg(prev);
            let theta = joint_angle(&a, &b, t.planar);
            let (ga, gb) = joint_angle_gradients(&a, &b, theta, t.planar);
            let r = sa * wrap_angle(theta - t.angles[i]);
            self.push(
                out,
                r,
                &[(prev, -sa * ga), (i, sa * (ga - gb)), (next, sa * gb)],
            );
            if !t.planar {
                for (du, dw) in transverse_rows(&a, &b, theta, t.angles[i]) {
                    let (du, dw) = (sa * du, sa * dw);
                    self.push(out, 0.0, &[(prev, -du), (i, du - dw), (next, dw)]);
                }
            }
        }
    }

    fn gradient_norm(&self, z: &[Real], _gradient: &[Real]) -> Real {
        let x = self.legs.variables(&self.points(z));
        let g = self.legs.energy_gradient(&x).1;
        g.iter().map(|v| v * v).sum::<Real>().sqrt()
    }
}

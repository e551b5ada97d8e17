//! Energy (14) of surface fine tuning as a sum of squares over the free
//! vertices' displacements, minimised by `levenberg_marquardt` (the default;
//! `surface_solve` keeps argmin's nonlinear CG).
//!
//! Residuals: `√k_l (l − l_opt)` per edge spring (`∂/∂x_b = √k_l (x_b − x_a)/l`),
//! `√k (θ − θ_opt)` per joint with the gradients of
//! [`angle_and_gradients`], so that `Σ r² = E` of eq. 14; every joint also
//! gets the two zero-valued curvature rows of `angle_curvature` (the loop
//! joints are straight at rest, where Gauss-Newton alone has no stiffness
//! across the loop's plane). Fixed vertices carry no variables.

use crate::math::{Point3, Real, Vector3};

use super::angle_curvature::transverse_rows;
use super::levenberg_marquardt::{LeastSquares, Residuals};
use super::surface_energy::{SpringEnergy, angle_and_gradients};

/// Energy (14) over the displacements `z` of the free vertices (3 per vertex).
pub struct SurfacePointProblem<'a> {
    energy: &'a SpringEnergy,
    start: &'a [Point3],
    /// First variable of each vertex; `None` for a fixed vertex.
    var_of: Vec<Option<usize>>,
    /// Jacobi scaling `s_v` per free vertex, for the reported gradient norm.
    scale: &'a [Real],
    free: &'a [usize],
}

impl<'a> SurfacePointProblem<'a> {
    /// The problem moving the vertices `free` of `start`; `scale` (one per
    /// free vertex) scales the gradient whose norm is tested.
    pub fn new(
        energy: &'a SpringEnergy,
        start: &'a [Point3],
        free: &'a [usize],
        scale: &'a [Real],
    ) -> Self {
        let mut var_of = vec![None; start.len()];
        for (k, &v) in free.iter().enumerate() {
            var_of[v] = Some(3 * k);
        }
        SurfacePointProblem {
            energy,
            start,
            var_of,
            scale,
            free,
        }
    }

    /// All vertex positions at displacements `z`.
    pub fn positions(&self, z: &[Real]) -> Vec<Point3> {
        let mut x = self.start.to_vec();
        for (k, &v) in self.free.iter().enumerate() {
            x[v] += Vector3::new(z[3 * k], z[3 * k + 1], z[3 * k + 2]);
        }
        x
    }

    /// Appends residual `r` with vertex gradients `(vertex, ∂r/∂x)`; the
    /// gradients of a vertex named twice (a joint's shared vertex) are
    /// summed, so that a row names each variable once.
    fn push(&self, out: &mut Residuals, r: Real, grads: &[(u32, Vector3)]) {
        let mut merged = [(0, Vector3::zeros()); 4];
        let mut count = 0;
        for &(v, g) in grads {
            match merged[..count].iter_mut().find(|e| e.0 == v) {
                Some(e) => e.1 += g,
                None => {
                    merged[count] = (v, g);
                    count += 1;
                }
            }
        }
        for &(v, g) in &merged[..count] {
            if let Some(base) = self.var_of[v as usize] {
                out.vars.extend_from_slice(&[base, base + 1, base + 2]);
                out.grads.extend_from_slice(&[g.x, g.y, g.z]);
            }
        }
        out.values.push(r);
        out.start.push(out.vars.len());
    }
}

impl LeastSquares for SurfacePointProblem<'_> {
    fn num_vars(&self) -> usize {
        3 * self.free.len()
    }

    fn nodes(&self) -> Vec<usize> {
        (0..3 * self.free.len()).map(|i| i / 3).collect()
    }

    fn energy(&self, z: &[Real]) -> Real {
        self.energy.energy(&self.positions(z))
    }

    fn residuals(&self, z: &[Real], out: &mut Residuals) {
        out.clear();
        let x = self.positions(z);
        let e = self.energy;
        let sl = e.k_l.sqrt();
        let zero = Vector3::zeros();
        for (k, &[a, b]) in e.edges.iter().enumerate() {
            let d = x[b as usize] - x[a as usize];
            let l = d.norm();
            let u = if l > 0.0 { d * (sl / l) } else { zero };
            let r = sl * (l - e.rest_lengths[k]);
            self.push(out, r, &[(b, u), (a, -u)]);
        }
        for (k, j) in e.joints.iter().enumerate() {
            let u = x[j[1] as usize] - x[j[0] as usize];
            let w = x[j[3] as usize] - x[j[2] as usize];
            let (theta, gu, gw) = angle_and_gradients(&u, &w);
            let s = e.joint_weights[k].sqrt();
            let rows = |gu: Vector3, gw: Vector3| {
                [
                    (j[1], gu * s),
                    (j[0], -gu * s),
                    (j[3], gw * s),
                    (j[2], -gw * s),
                ]
            };
            self.push(out, s * (theta - e.rest_angles[k]), &rows(gu, gw));
            for (du, dw) in transverse_rows(&u, &w, theta, e.rest_angles[k]) {
                self.push(out, 0.0, &rows(du, dw));
            }
        }
    }

    fn gradient_norm(&self, _z: &[Real], gradient: &[Real]) -> Real {
        gradient
            .iter()
            .enumerate()
            .map(|(i, g)| (g * self.scale[i / 3]).powi(2))
            .sum::<Real>()
            .sqrt()
    }
}

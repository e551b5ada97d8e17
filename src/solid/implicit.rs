//! Implicit (backward Euler) integrator on the control-point system, solved
//! by preconditioned conjugate gradients.
//!
//! Backward Euler with the forces linearised at the start of the step
//! (Baraff & Witkin 1998, eq. 6–7), projected onto the free control points
//! with `ḋ = A₁ ṗ₁`:
//! `(M̂ + h D̂ + h² K̂) Δṗ₁ = h A₁ᵀ (f − h K A₁ ṗ₁)`,
//! `M̂ = A₁ᵀ M A₁`, `D̂ = γ M̂`, `K̂ = A₁ᵀ K A₁`, `K` the springs' and ropes'
//! Hessian at `d` (transverse terms clamped, so the matrix is SPD), `f` the
//! mass-point forces of [`Solid::step_explicit`]; then `ṗ₁ += Δṗ₁`,
//! `p₁ += h ṗ₁`. CG starts from the previous step's `Δṗ₁` and runs matrix-free
//! (one `A₁`, one Hessian and one `A₁ᵀ` product per iteration; the spring
//! Hessians are computed once per step) with the preconditioner
//! `P = (1 + hγ) M̂ + h² A₁ᵀ L A₁`, `L = Σ k_s b_s b_sᵀ` the isotropic spring
//! Laplacian (the rest-state Hessian with every spring direction replaced by
//! the identity), factored once per time step, material and partition.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::math::{Real, Vector3};
use crate::stencil::StencilTable;

use super::explicit::{StepReport, check_step};
use super::model::{Preconditioner, Solid};
use super::products::{cholesky, dot, mul_transpose_vectors, mul_vectors, solve_vectors};
use super::springs::SpringHessians;

impl Solid {
    /// The preconditioner for step `h`, built if the cache does not hold it.
    fn preconditioner(&mut self, h: Real) -> Result<()> {
        if self.precond.as_ref().is_some_and(|p| p.h == h) || self.part.free.is_empty() {
            return Ok(());
        }
        let scale = 1.0 + h * self.params.damping;
        let mut rows = self.springs.laplacian_rows(self.params.stiffness);
        for (i, row) in rows.iter_mut().enumerate() {
            for e in row.iter_mut() {
                e.1 *= h * h;
            }
            row.push((i as u32, scale * self.mass[i]));
        }
        let l = StencilTable::from_rows(self.d.len(), &rows);
        let p = self.part.a1t.compose(&l.compose(&self.part.a1)?)?;
        self.precond = Some(Preconditioner {
            h,
            factor: cholesky(&p, "implicit preconditioner")?,
        });
        Ok(())
    }

    /// `K w` of the springs and ropes at the current mass points.
    fn stiffness_product(&self, hess: &SpringHessians, w: &[Vector3], out: &mut [Vector3]) {
        out.iter_mut().for_each(|o| *o = Vector3::zeros());
        self.springs.add_hessian_product(hess, w, out);
        for r in &self.ropes {
            out[r.point] += r.hessian_times(&self.d, w[r.point]);
        }
    }

    /// Advances the solid by `h` with backward Euler (see the module docs).
    pub fn step_implicit(&mut self, h: Real) -> Result<StepReport> {
        check_step(self, h)?;
        let start = Instant::now();
        self.preconditioner(h)?;
        let (f, spring_energy) = self.mass_point_forces();
        let free = self.part.free.clone();
        let Some(pre) = &self.precond else {
            self.time += h;
            return Ok(StepReport {
                seconds: start.elapsed().as_secs_f64(),
                spring_energy,
                ..StepReport::default()
            });
        };
        let nd = self.d.len();
        let scale = 1.0 + h * self.params.damping;
        let mut kw = vec![Vector3::zeros(); nd];
        // b = h A₁ᵀ (f − h K ḋ)
        let mut hess = std::mem::take(&mut self.hess);
        self.springs
            .hessians_into(&self.d, self.params.stiffness, &mut hess);
        self.stiffness_product(&hess, &self.dd, &mut kw);
        let rhs_fine: Vec<Vector3> = f.iter().zip(&kw).map(|(f, k)| (f - k * h) * h).collect();
        let b = mul_transpose_vectors(&self.part.a1, &rhs_fine);
        let mut w = vec![Vector3::zeros(); nd];
        let mut fine = vec![Vector3::zeros(); nd];
        let mut apply = |x: &[Vector3]| -> Vec<Vector3> {
            mul_vectors(&self.part.a1, x, &mut w);
            self.stiffness_product(&hess, &w, &mut kw);
            for i in 0..nd {
                fine[i] = w[i] * (scale * self.mass[i]) + kw[i] * (h * h);
            }
            mul_transpose_vectors(&self.part.a1, &fine)
        };
        // Preconditioned CG, warm-started from the previous step's Δṗ₁.
        let n = free.len();
        let mut x = if self.last_dv.len() == n {
            self.last_dv.clone()
        } else {
            vec![Vector3::zeros(); n]
        };
        let b_norm = dot(&b, &b).sqrt();
        let ax = apply(&x);
        let mut r: Vec<Vector3> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
        let mut z = solve_vectors(&pre.factor, &r);
        let mut dir = z.clone();
        let mut rz = dot(&r, &z);
        let mut iterations = 0;
        let mut residual = if b_norm > 0.0 {
            dot(&r, &r).sqrt() / b_norm
        } else {
            0.0
        };
        if b_norm == 0.0 {
            x.iter_mut().for_each(|v| *v = Vector3::zeros());
        }
        let tol = self.params.cg_tolerance;
        while residual > tol && iterations < self.params.cg_max_iterations {
            let q = apply(&dir);
            let dq = dot(&dir, &q);
            if !(dq > 0.0 && dq.is_finite()) {
                return Err(Error::NotConverged(format!(
                    "implicit step: CG met a non-positive curvature {dq:.3e} at iteration {iterations}"
                )));
            }
            let alpha = rz / dq;
            for k in 0..n {
                x[k] += dir[k] * alpha;
                r[k] -= q[k] * alpha;
            }
            iterations += 1;
            residual = dot(&r, &r).sqrt() / b_norm;
            z = solve_vectors(&pre.factor, &r);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for k in 0..n {
                dir[k] = z[k] + dir[k] * beta;
            }
        }
        for (k, &i) in free.iter().enumerate() {
            self.v[i] += x[k];
            self.p[i] += self.v[i] * h;
        }
        self.last_dv = x;
        self.hess = hess;
        self.refresh();
        self.time += h;
        Ok(StepReport {
            seconds: start.elapsed().as_secs_f64(),
            iterations,
            residual,
            spring_energy,
        })
    }
}

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
//! `p₁ += h ṗ₁`. CG runs matrix-free
//! (one `A₁`, one Hessian and one `A₁ᵀ` product per iteration; the spring
//! Hessians are computed once per step, in the same pass over the springs as
//! the forces and `K ḋ`). Preconditioners
//! ([`ImplicitPreconditioner`]):
//! - the lagged Hessian (default): the step's own matrix
//!   `A₁ᵀ ((1 + hγ) M + h² K) A₁` assembled densely ([`reduced`](super::reduced))
//!   at the step where it is built (which then converges in one iteration)
//!   and reused, with the Hessian of that step, until the CG iterations
//!   beyond the first, summed since then, exceed
//!   [`SolidParams::preconditioner_refresh`](super::SolidParams::preconditioner_refresh);
//!   the next step rebuilds it. CG starts from zero;
//! - the spring Laplacian `P = (1 + hγ) M̂ + h² A₁ᵀ L A₁`,
//!   `L = Σ k_s b_s b_sᵀ` (the rest-state Hessian with every spring direction
//!   replaced by the identity), factored once per time step, material and
//!   partition. CG starts from the previous step's `Δṗ₁`.
//!
//! Both are rebuilt when the time step, the material or the partition
//! changes. The preconditioner changes only how fast CG reaches its
//! tolerance, not the system it solves.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::linalg::{CgStop, cg};
use crate::math::{Real, Vector3};
use crate::stencil::StencilTable;

use super::explicit::{StepReport, check_step};
use super::model::{PrecondFactor, Preconditioner, Solid};
use super::params::ImplicitPreconditioner;
use super::products::{cholesky, cholesky_dense, solve_vectors};
use super::reduced::{BlockPattern, MAX_DENSE_UNKNOWNS, ReducedInputs, reduced_matrix};
use super::springs::SpringHessians;

/// `z = P⁻¹ r` with a factored preconditioner.
impl crate::linalg::Preconditioner<Vector3> for PrecondFactor {
    fn apply(&self, r: &[Vector3]) -> Vec<Vector3> {
        match self {
            PrecondFactor::Laplacian(f) => solve_vectors(f, r),
            PrecondFactor::Hessian(f) => {
                let mut b = nalgebra::DVector::from_iterator(
                    3 * r.len(),
                    r.iter().flat_map(|v| [v.x, v.y, v.z]),
                );
                f.solve_mut(&mut b);
                b.as_slice()
                    .chunks_exact(3)
                    .map(|c| Vector3::new(c[0], c[1], c[2]))
                    .collect()
            }
        }
    }
}

impl Solid {
    /// Builds the preconditioner for step `h` (the lagged one at the
    /// Hessians `hess`) unless the cache holds a usable one; true when built.
    fn preconditioner(&mut self, h: Real, hess: &SpringHessians) -> Result<bool> {
        let n = self.part.free.len();
        if n == 0 {
            return Ok(false);
        }
        let dense = self.params.preconditioner == ImplicitPreconditioner::LaggedHessian
            && 3 * n <= MAX_DENSE_UNKNOWNS;
        if let Some(p) = &self.precond {
            let same_kind = matches!(p.factor, PrecondFactor::Hessian(_)) == dense;
            if p.h == h && same_kind && !p.stale {
                return Ok(false);
            }
        }
        let scale = 1.0 + h * self.params.damping;
        let factor = if dense {
            let pattern = self
                .pattern
                .get_or_insert_with(|| BlockPattern::new(&self.springs));
            let inputs = ReducedInputs {
                hess,
                ropes: &self.ropes,
                d: &self.d,
                mass: &self.mass,
                mass_scale: scale,
                h2: h * h,
            };
            let m = reduced_matrix(pattern, &self.part.a1, &inputs);
            PrecondFactor::Hessian(cholesky_dense(m, "implicit step's matrix")?)
        } else {
            let mut rows = self.springs.laplacian_rows(self.params.stiffness);
            for (i, row) in rows.iter_mut().enumerate() {
                for e in row.iter_mut() {
                    e.1 *= h * h;
                }
                row.push((i as u32, scale * self.mass[i]));
            }
            let l = StencilTable::from_rows(self.d.len(), &rows);
            let p = self.part.a1t.compose(&l.compose(&self.part.a1)?)?;
            PrecondFactor::Laplacian(cholesky(&p, "implicit preconditioner")?)
        };
        self.precond = Some(Preconditioner {
            h,
            factor,
            excess: 0,
            stale: false,
        });
        Ok(true)
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
        // f − h K ḋ (forces, damping, ropes) and the Hessians in one pass.
        let mut f = self.damping_forces();
        let mut hess = std::mem::take(&mut self.hess);
        let spring_energy = self.springs.add_forces_minus_hessian_product(
            &self.d,
            &self.dd,
            self.params.stiffness,
            h,
            &mut f,
            &mut hess,
        );
        for r in &self.ropes {
            f[r.point] +=
                r.force_energy(&self.d).0 - r.hessian_times(&self.d, self.dd[r.point]) * h;
        }
        let built = self.preconditioner(h, &hess);
        let result = self.solve_step(h, &f, &hess, built);
        self.hess = hess;
        let (iterations, residual, refreshed) = result?;
        self.time += h;
        Ok(StepReport {
            seconds: start.elapsed().as_secs_f64(),
            iterations,
            residual,
            spring_energy,
            refreshed,
        })
    }

    /// CG on the step's system and the update of `ṗ₁`, `p₁`: iterations,
    /// final relative residual, whether the preconditioner was (re)built.
    fn solve_step(
        &mut self,
        h: Real,
        f_minus_hkv: &[Vector3],
        hess: &SpringHessians,
        built: Result<bool>,
    ) -> Result<(usize, Real, bool)> {
        let built = built?;
        let Some(pre) = &self.precond else {
            return Ok((0, 0.0, false));
        };
        if self.part.free.is_empty() {
            return Ok((0, 0.0, false));
        }
        let nd = self.d.len();
        let scale = 1.0 + h * self.params.damping;
        let mut kw = vec![Vector3::zeros(); nd];
        // b = h A₁ᵀ (f − h K ḋ), `f_minus_hkv` holding the bracket.
        let rhs_fine: Vec<Vector3> = f_minus_hkv.iter().map(|f| f * h).collect();
        let b = self.part.a1.apply_transpose_parallel(&rhs_fine);
        let mut w = vec![Vector3::zeros(); nd];
        let mut fine = vec![Vector3::zeros(); nd];
        let mut apply = |x: &[Vector3]| -> Vec<Vector3> {
            self.part.a1.apply_into(x, &mut w);
            self.stiffness_product(hess, &w, &mut kw);
            for i in 0..nd {
                fine[i] = w[i] * (scale * self.mass[i]) + kw[i] * (h * h);
            }
            self.part.a1.apply_transpose_parallel(&fine)
        };
        // Preconditioned CG, from zero with the lagged Hessian (its first
        // iterate `P⁻¹ b` is already close; a warm start would cost one more
        // product), else warm-started from the previous step's Δṗ₁.
        let n = self.part.free.len();
        let warm = matches!(pre.factor, PrecondFactor::Laplacian(_));
        let mut x = if self.last_dv.len() == n && warm {
            self.last_dv.clone()
        } else {
            vec![Vector3::zeros(); n]
        };
        let stop = CgStop {
            tolerance: self.params.cg_tolerance,
            max_iterations: self.params.cg_max_iterations,
        };
        let outcome = cg(|v| Ok(apply(v)), &pre.factor, &b, &mut x, &stop)?.map_err(|e| {
            Error::NotConverged(format!(
                "implicit step: conjugate gradients stopped at iteration {}: {}",
                e.iteration, e.what
            ))
        })?;
        let (iterations, residual) = (outcome.iterations[0], outcome.relative[0]);
        if let Some(p) = self.precond.as_mut() {
            p.excess += iterations.saturating_sub(1);
            p.stale = matches!(p.factor, PrecondFactor::Hessian(_))
                && p.excess > self.params.preconditioner_refresh;
        }
        for (k, &i) in self.part.free.iter().enumerate() {
            self.v[i] += x[k];
            self.p[i] += self.v[i] * h;
        }
        self.last_dv = x;
        self.refresh();
        Ok((iterations, residual, built))
    }
}

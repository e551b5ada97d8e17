//! The explicit integrator of McDonnell & Qin, §4.3: forces on the mass
//! points, control-point accelerations from eq. 6,
//! `p̈₁ = (A₁ᵀ M A₁)⁻¹ A₁ᵀ (f_d − D ḋ + f_springs)`, with the constant
//! `A₁ᵀ M A₁` factored once (Cholesky), then an Euler update of `ṗ₁`, `p₁`
//! ([`ExplicitScheme`]) and `d = A p`, `ḋ = A ṗ`.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::math::Real;

use super::model::Solid;
use super::params::{ExplicitScheme, check_value};
use super::products::solve_vectors;

/// What one time step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Wall time of the step in seconds.
    pub seconds: Real,
    /// CG iterations (0 for the explicit integrator).
    pub iterations: usize,
    /// Final relative CG residual (0 for the explicit integrator).
    pub residual: Real,
    /// Spring energy at the start of the step.
    pub spring_energy: Real,
    /// The implicit step (re)built its preconditioner.
    pub refreshed: bool,
}

/// Errors unless `h` is a usable time step and the state is finite.
pub(crate) fn check_step(solid: &Solid, h: Real) -> Result<()> {
    check_value("time step", h, true)?;
    if solid
        .p
        .iter()
        .any(|p| !p.coords.iter().all(|x| x.is_finite()))
        || solid.v.iter().any(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Err(Error::NotConverged(format!(
            "the solid's state is no longer finite at t = {} (the time step is unstable)",
            solid.time
        )));
    }
    Ok(())
}

impl Solid {
    /// Advances the solid by `h` with the explicit integrator.
    pub fn step_explicit(&mut self, h: Real) -> Result<StepReport> {
        check_step(self, h)?;
        let start = Instant::now();
        let (f, spring_energy) = self.mass_point_forces();
        if let Some(factor) = &self.part.mass_factor {
            let g = self.part.a1.apply_transpose_parallel(&f);
            let acc = solve_vectors(factor, &g);
            for (k, &i) in self.part.free.iter().enumerate() {
                let old = self.v[i];
                self.v[i] += acc[k] * h;
                let vel = match self.params.scheme {
                    ExplicitScheme::SymplecticEuler => self.v[i],
                    ExplicitScheme::ForwardEuler => old,
                };
                self.p[i] += vel * h;
            }
        }
        self.refresh();
        self.time += h;
        Ok(StepReport {
            seconds: start.elapsed().as_secs_f64(),
            iterations: 0,
            residual: 0.0,
            spring_energy,
            refreshed: false,
        })
    }
}

//! `SolidParams`: material and solver parameters of a dynamic subdivision
//! solid, with documented defaults and a validity check.

use crate::error::{Error, Result};
use crate::math::Real;

use super::model::MAX_SOLID_LEVEL;
use super::springs::Stiffness;

/// How the explicit integrator advances positions (McDonnell & Qin, §4.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExplicitScheme {
    /// Semi-implicit (symplectic) Euler, the default:
    /// `ṗ_{i+1} = ṗ_i + p̈_i Δt`, `p_{i+1} = p_i + ṗ_{i+1} Δt`. Stable for
    /// `Δt < 2/ω_max` even without damping, energy bounded.
    #[default]
    SymplecticEuler,
    /// The update as printed in §4.3, `p_{i+1} = p_i + ṗ_i Δt` (forward
    /// Euler): its amplification factor `|1 + iωΔt| > 1` makes every
    /// undamped oscillation grow, so it needs damping to be stable at all.
    ForwardEuler,
}

/// The preconditioner of the implicit step's CG.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ImplicitPreconditioner {
    /// The step's own matrix `A₁ᵀ ((1 + hγ) M + h² K) A₁`, assembled densely
    /// at one step's Hessian, factored and reused by the following steps
    /// until their CG iterations beyond the first add up to more than
    /// [`preconditioner_refresh`](SolidParams::preconditioner_refresh)
    /// (the default; used while there are at most
    /// [`MAX_DENSE_UNKNOWNS`](super::MAX_DENSE_UNKNOWNS) unknowns, the
    /// spring Laplacian beyond).
    #[default]
    LaggedHessian,
    /// `(1 + hγ) A₁ᵀ M A₁ + h² A₁ᵀ L A₁`, `L = Σ k_s b_s b_sᵀ` the isotropic
    /// spring Laplacian, one scalar system per coordinate, factored once per
    /// time step, material and partition.
    Laplacian,
}

/// Parameters of a [`Solid`](super::Solid).
#[derive(Clone, Debug, PartialEq)]
pub struct SolidParams {
    /// Refinement level `L` of the mass-point lattice (default 2; 0 to 4).
    pub level: usize,
    /// Mass density `μ`: a cell of volume `V` carries mass `μ V`, shared by
    /// its vertices (default 1).
    pub density: Real,
    /// Spring stiffness per unit rest length, normal and virtual (default 400 and 400).
    pub stiffness: Stiffness,
    /// Damping `γ` per unit mass: `D = γ M` (default 2).
    pub damping: Real,
    /// Explicit scheme (default [`ExplicitScheme::SymplecticEuler`]).
    pub scheme: ExplicitScheme,
    /// Relative residual at which the implicit step's CG stops (default 1e-6).
    pub cg_tolerance: Real,
    /// CG iteration limit of the implicit step (default 500).
    pub cg_max_iterations: usize,
    /// Preconditioner of the implicit step's CG (default
    /// [`ImplicitPreconditioner::LaggedHessian`]).
    pub preconditioner: ImplicitPreconditioner,
    /// The lagged Hessian preconditioner is rebuilt at the next step once
    /// the CG iterations beyond the first, summed over the steps since it
    /// was built, exceed this (default 10; on the 4,913-point cube a rebuild
    /// costs as much as some 10 to 30 CG iterations). Rebuilding once the
    /// extra iterations have cost about one rebuild balances the two when
    /// the iterations grow steadily with the lag.
    pub preconditioner_refresh: usize,
}

impl Default for SolidParams {
    fn default() -> Self {
        SolidParams {
            level: 2,
            density: 1.0,
            stiffness: Stiffness {
                edge: 400.0,
                virtual_: 400.0,
            },
            damping: 2.0,
            scheme: ExplicitScheme::SymplecticEuler,
            cg_tolerance: 1e-6,
            cg_max_iterations: 500,
            preconditioner: ImplicitPreconditioner::LaggedHessian,
            preconditioner_refresh: 10,
        }
    }
}

/// Errors unless `x` is finite, at most 1e12 and `≥ 0` (or `> 0` when
/// `positive`); `name` names the value in the message. Every stiffness,
/// damping, density and rope value of a solid is checked with it.
pub fn check_value(name: &str, x: Real, positive: bool) -> Result<()> {
    let ok = x.is_finite() && if positive { x > 0.0 } else { x >= 0.0 };
    if !ok || x > 1e12 {
        return Err(Error::input(format!(
            "{name} = {x}: expected a finite {} number up to 1e12",
            if positive { "positive" } else { "non-negative" }
        )));
    }
    Ok(())
}

impl SolidParams {
    /// Checks every value: level 0 to [`MAX_SOLID_LEVEL`], positive density,
    /// non-negative stiffnesses and damping, tolerance in (0, 1), 1 to 100,000
    /// CG iterations, a preconditioner refresh threshold of at least 1.
    pub fn check(&self) -> Result<()> {
        if self.level > MAX_SOLID_LEVEL {
            return Err(Error::input(format!(
                "level {} is too fine for a solid (at most {MAX_SOLID_LEVEL})",
                self.level
            )));
        }
        check_value("density", self.density, true)?;
        check_value("normal spring stiffness", self.stiffness.edge, false)?;
        check_value("virtual spring stiffness", self.stiffness.virtual_, false)?;
        check_value("damping", self.damping, false)?;
        if !(self.cg_tolerance > 0.0 && self.cg_tolerance < 1.0) {
            return Err(Error::input(format!(
                "CG tolerance {} must lie in (0, 1)",
                self.cg_tolerance
            )));
        }
        if self.preconditioner_refresh == 0 {
            return Err(Error::input(
                "preconditioner refresh after 0 extra CG iterations: expected at least 1",
            ));
        }
        if self.cg_max_iterations == 0 || self.cg_max_iterations > 100_000 {
            return Err(Error::input(format!(
                "{} CG iterations: expected 1 to 100,000",
                self.cg_max_iterations
            )));
        }
        Ok(())
    }
}

//! Implicit time integration of a dynamic Catmull-Clark surface (Qin,
//! Mandal, Vemuri 1998, eq. 16 and §III-C) for interactive use: a drag
//! spring, inflation or any other load, step after step.
//!
//! Each step is the linear system of eq. 16 ([`ImplicitSystem`]): a backward
//! Euler step, which dissipates: multiplying it by `p⁺ − p` gives, for fixed
//! springs `S` and load `f`,
//! `E(p⁺, p) − E(p, p⁻) = −½‖v⁺ − v‖²_M − Δt‖v⁺‖²_D − ½‖p⁺ − p‖²_{K+S}`
//! with `E(p, p⁻) = ½ vᵀ M v + ½ pᵀ (K + S) p − fᵀ p`, `v = (p − p⁻)/Δt`
//! ([`SurfaceDynamics::energy`]): the energy never rises, which is what
//! equilibrium detection by energy change relies on.
//!
//! The step's matrix changes only when `S` does. [`LinearSolver::Cholesky`]
//! factors it then and reuses the factor for every step with the same
//! matrix (a drag spring held at one surface point while its target moves):
//! two triangular solves per step. [`LinearSolver::Pcg`] solves each step by
//! conjugate gradients from the current positions, which suits a matrix that
//! changes every step (the fit's data springs).

use crate::error::{Error, Result};
use crate::limit::PatchTable;
use crate::linalg::SparseCholesky;
use crate::math::{Point3, Real, first_non_finite};
use crate::stencil::StencilTable;

use super::elements::patch_matrices;
use super::implicit::ImplicitSystem;
use super::matrices::MaterialParams;
use super::pcg::{PcgParams, pcg};

/// How an implicit step's linear system is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LinearSolver {
    /// Jacobi-preconditioned conjugate gradients from the current positions.
    Pcg(PcgParams),
    /// Sparse Cholesky, factored when the step's matrix changes and reused
    /// while it does not.
    Cholesky,
}

/// What one step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// [`SurfaceDynamics::energy`] after the step.
    pub energy: Real,
    /// Its change over the step relative to its size before (the
    /// equilibrium test: settled when below a tolerance).
    pub relative_change: Real,
    /// Conjugate-gradient iterations (0 with Cholesky).
    pub cg_iterations: usize,
    /// True when the step factored its matrix (Cholesky only).
    pub factored: bool,
}

/// A dynamic surface: mass, damping and stiffness over its control points,
/// its positions now and one step before, and the solver's state.
#[derive(Clone, Debug)]
pub struct SurfaceDynamics {
    stiffness: StencilTable,
    /// `M/Δt² + D/Δt + K`, `D/Δt` and `M/Δt²`.
    implicit: ImplicitSystem,
    solver: LinearSolver,
    p: Vec<Point3>,
    p_before: Vec<Point3>,
    /// The matrix factored last and its factor.
    factored: Option<(StencilTable, SparseCholesky)>,
    factorizations: usize,
}

impl SurfaceDynamics {
    /// A surface at rest at `positions` with mass `mass` (`∫∫ μ JᵀJ`; `None`:
    /// the first-order, massless dynamics), damping `damping` (`∫∫ γ JᵀJ`)
    /// and stiffness `stiffness` (all `n × n` over the `n` control points),
    /// stepped by `dt`.
    pub fn new(
        mass: Option<StencilTable>,
        damping: StencilTable,
        stiffness: StencilTable,
        positions: Vec<Point3>,
        dt: Real,
        solver: LinearSolver,
    ) -> Result<SurfaceDynamics> {
        let n = positions.len();
        for (name, m) in [
            ("damping", Some(&damping)),
            ("stiffness", Some(&stiffness)),
            ("mass", mass.as_ref()),
        ] {
            check_size(name, m, n)?;
        }
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(Error::input(format!(
                "dynamics: time step {dt} must be positive"
            )));
        }
        if let Some(i) = first_non_finite(&positions) {
            return Err(Error::non_finite(format!(
                "dynamics: control point {i} is not finite"
            )));
        }
        let scaled = |m: &StencilTable, s: Real| StencilTable {
            weights: m.weights.iter().map(|w| s * w).collect(),
            ..m.clone()
        };
        let damping = scaled(&damping, 1.0 / dt);
        let mass = mass.map(|m| scaled(&m, 1.0 / (dt * dt)));
        let mut base = stiffness.linear_combination(1.0, &damping, 1.0)?;
        if let Some(m) = &mass {
            base = base.linear_combination(1.0, m, 1.0)?;
        }
        Ok(SurfaceDynamics {
            implicit: ImplicitSystem {
                base,
                damping,
                mass,
            },
            stiffness,
            solver,
            p_before: positions.clone(),
            p: positions,
            factored: None,
            factorizations: 0,
        })
    }

    /// [`SurfaceDynamics::new`] with the matrices assembled patch by patch
    /// over `table` (the closest-point engine's patches) with
    /// Gauss-Legendre `order` × `order` points per polynomial piece
    /// ([`patch_matrices`], over `du dv`): `materials` holds one material or
    /// one per base face; no mass matrix when every `μ` is 0.
    pub fn on_patches(
        table: &PatchTable,
        positions: Vec<Point3>,
        materials: &[MaterialParams],
        order: usize,
        dt: Real,
        solver: LinearSolver,
    ) -> Result<SurfaceDynamics> {
        let [mass, damping, stiffness] = patch_matrices(table, order, materials)?;
        let mass = materials.iter().any(|m| m.mu > 0.0).then_some(mass);
        SurfaceDynamics::new(mass, damping, stiffness, positions, dt, solver)
    }

    /// The control points now.
    pub fn positions(&self) -> &[Point3] {
        &self.p
    }

    /// Sets the control points (a jump: the surface is at rest there).
    pub fn set_positions(&mut self, positions: &[Point3]) -> Result<()> {
        if positions.len() != self.p.len() {
            return Err(Error::size_mismatch(format!(
                "dynamics: {} positions for {} control points",
                positions.len(),
                self.p.len()
            )));
        }
        self.p = positions.to_vec();
        self.p_before = positions.to_vec();
        Ok(())
    }

    /// Matrices factored so far (Cholesky only).
    pub fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// `E = ½ vᵀ M v + ½ pᵀ (K + S) p − fᵀ p` with `v = (p − p⁻)/Δt`: kinetic
    /// plus potential energy for implicit stiffness `springs` (`S`, `None`:
    /// none) and load `load` (`f`), up to a constant (with data springs the
    /// potential part is `½ pᵀ K p + ½ Σ k |J p − d|²` less `½ Σ k |d|²`).
    pub fn energy(&self, springs: Option<&StencilTable>, load: &[Point3]) -> Result<Real> {
        self.check_load(springs, load)?;
        let dot = |a: &[Point3], b: &[Point3]| -> Real {
            a.iter().zip(b).map(|(a, b)| a.coords.dot(&b.coords)).sum()
        };
        let mut e = 0.5 * dot(&self.stiffness.apply(&self.p)?, &self.p) - dot(load, &self.p);
        if let Some(s) = springs {
            e += 0.5 * dot(&s.apply(&self.p)?, &self.p);
        }
        if let Some(m) = &self.implicit.mass {
            // `M/Δt²` on `p − p⁻`: `½ vᵀ M v` with `v = (p − p⁻)/Δt`.
            let v: Vec<Point3> = self
                .p
                .iter()
                .zip(&self.p_before)
                .map(|(a, b)| Point3::from(a - b))
                .collect();
            e += 0.5 * dot(&m.apply(&v)?, &v);
        }
        Ok(e)
    }

    /// One implicit step with implicit stiffness `springs` (`S`) and load
    /// `load` (`f`, one vector per control point).
    pub fn step(&mut self, springs: Option<&StencilTable>, load: &[Point3]) -> Result<StepReport> {
        let before = self.energy(springs, load)?;
        let (a, rhs) = self
            .implicit
            .system(springs.cloned(), &[load], &self.p, &self.p_before)?;
        let (next, cg_iterations, factored) = match self.solver {
            LinearSolver::Pcg(params) => {
                let mut x = self.p.clone();
                let report = pcg(&a, &rhs, &mut x, &params)?;
                if !report.converged {
                    return Err(Error::NotConverged(format!(
                        "dynamics: conjugate gradients stopped at relative residual {:e} after {} iterations",
                        report.relative_residual, report.iterations
                    )));
                }
                (x, report.iterations, false)
            }
            LinearSolver::Cholesky => {
                let same = self.factored.as_ref().is_some_and(|(f, _)| {
                    f.offsets == a.offsets && f.indices == a.indices && f.weights == a.weights
                });
                if !same {
                    match &mut self.factored {
                        Some((f, factor)) => {
                            factor.refactor(&a)?;
                            *f = a;
                        }
                        None => self.factored = Some((a.clone(), SparseCholesky::new(&a)?)),
                    }
                    self.factorizations += 1;
                }
                let (_, factor) = self.factored.as_ref().expect("factored above");
                (factor.solve(&rhs)?, 0, !same)
            }
        };
        if let Some(i) = first_non_finite(&next) {
            return Err(Error::NotConverged(format!(
                "dynamics: the step gave a non-finite position at control point {i}"
            )));
        }
        self.p_before = std::mem::replace(&mut self.p, next);
        let energy = self.energy(springs, load)?;
        Ok(StepReport {
            energy,
            relative_change: (before - energy).abs() / before.abs().max(Real::MIN_POSITIVE),
            cg_iterations,
            factored,
        })
    }

    fn check_load(&self, springs: Option<&StencilTable>, load: &[Point3]) -> Result<()> {
        let n = self.p.len();
        if load.len() != n {
            return Err(Error::size_mismatch(format!(
                "dynamics: a load of {} vectors for {n} control points",
                load.len()
            )));
        }
        if let Some(i) = first_non_finite(load) {
            return Err(Error::non_finite(format!(
                "dynamics: the load on control point {i} is not finite"
            )));
        }
        check_size("spring", springs, n)
    }
}

/// An error unless `m` (when given) is `n × n`.
fn check_size(name: &str, m: Option<&StencilTable>, n: usize) -> Result<()> {
    match m {
        Some(m) if m.num_rows() != n || m.num_cols != n => Err(Error::size_mismatch(format!(
            "dynamics: the {name} matrix is {} × {} for {n} control points",
            m.num_rows(),
            m.num_cols
        ))),
        _ => Ok(()),
    }
}

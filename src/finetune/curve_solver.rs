//! Minimising energy (13) with argmin's nonlinear conjugate gradient
//! (Polak-Ribière+, More-Thuente line search), over a reduced set of
//! variables that fixes one point and one rotation.
//!
//! The variables are the legs of the polygon walked from the fixed point
//! (see `curve_frames`): `d_t = Σ_v x_v e_v`, `C` the prefix sums, so the
//! gradient in `x` is `e_v · Σ_{s>t} ∂E/∂p_s` (suffix sums).
//!
//! argmin 0.11 stops only on iteration count or target cost, so the solver
//! is wrapped in [`Converging`], which also stops when `|∇E| ≤ tolerance`,
//! or when the energy has stalled at rounding level (it fell by less than
//! `1e-14 E` over the last [`STALL_WINDOW`] iterations, so `E` can no longer
//! resolve progress), and records the energy after every iteration.

use std::sync::{Arc, Mutex};

use argmin::core::{
    CostFunction, Error as ArgminError, Gradient, IterState, KV, Problem, Solver, State,
    TerminationReason, TerminationStatus,
};
use nalgebra::DVector;

use crate::math::{Point3, Real, Vector3};

use super::curve_energy::SpringTargets;

/// How one leg depends on the variables: `d_t = Σ_v x_v e_v`.
#[derive(Clone, Debug)]
pub struct LegFrame {
    /// The `e_v` (1 to 3), each with the index of its variable.
    pub axes: Vec<(usize, Vector3)>,
}

/// The energy over the reduced variables (legs walked from the fixed point,
/// see `curve_frames`), as an argmin problem.
#[derive(Clone, Debug)]
pub struct SpringProblem {
    /// The fixed control point `C_f`.
    pub origin: Point3,
    /// Its index `f`.
    pub fixed: usize,
    /// Frames of legs `d_0 … d_{N−2}` in walking order.
    pub legs: Vec<LegFrame>,
    /// Number of variables.
    pub num_vars: usize,
    /// Targets and weights of energy (13).
    pub targets: SpringTargets,
}

impl SpringProblem {
    /// Control points `C_0 … C_{N−1}` for variables `x`.
    pub fn points(&self, x: &[Real]) -> Vec<Point3> {
        let n = self.legs.len() + 1;
        let mut out = vec![self.origin; n];
        let mut p = self.origin;
        for (t, leg) in self.legs.iter().enumerate() {
            p = leg.axes.iter().fold(p, |p, (v, e)| p + x[*v] * e);
            out[(self.fixed + t + 1) % n] = p;
        }
        out
    }

    /// The variables that reproduce `points` (which must satisfy the gauge:
    /// `points[fixed] = origin`, every leg in the span of its axes).
    pub fn variables(&self, points: &[Point3]) -> Vec<Real> {
        let n = points.len();
        let mut x = vec![0.0; self.num_vars];
        for (t, leg) in self.legs.iter().enumerate() {
            let d = points[(self.fixed + t + 1) % n] - points[(self.fixed + t) % n];
            for (v, a) in &leg.axes {
                x[*v] = d.dot(a) / a.norm_squared();
            }
        }
        x
    }

    /// Energy and gradient in the variables: `∂E/∂d_t = Σ_{s>t} ∂E/∂p_s`.
    pub fn energy_gradient(&self, x: &[Real]) -> (Real, Vec<Real>) {
        let points = self.points(x);
        let n = points.len();
        let mut g = vec![Vector3::zeros(); n];
        let e = self.targets.energy(&points, Some(&mut g));
        let mut gx = vec![0.0; self.num_vars];
        let mut suffix = Vector3::zeros();
        for (t, leg) in self.legs.iter().enumerate().rev() {
            suffix += g[(self.fixed + t + 1) % n];
            for (v, axis) in &leg.axes {
                gx[*v] += axis.dot(&suffix);
            }
        }
        (e, gx)
    }
}

impl CostFunction for SpringProblem {
    type Param = DVector<Real>;
    type Output = Real;
    fn cost(&self, x: &Self::Param) -> Result<Real, ArgminError> {
        Ok(self.targets.energy(&self.points(x.as_slice()), None))
    }
}

impl Gradient for SpringProblem {
    type Param = DVector<Real>;
    type Gradient = DVector<Real>;
    fn gradient(&self, x: &Self::Param) -> Result<Self::Gradient, ArgminError> {
        Ok(DVector::from_vec(self.energy_gradient(x.as_slice()).1))
    }
}

/// Energies after each iteration (index 0: the start) and the last parameters.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// `E` at the start and after each iteration.
    pub energies: Vec<Real>,
    /// Gradient norm at the start and after each iteration.
    pub gradient_norms: Vec<Real>,
    /// The parameters after the last completed iteration.
    pub last: Option<DVector<Real>>,
}

/// Iterations over which a stalled energy is detected.
pub const STALL_WINDOW: usize = 20;
/// Relative energy decrease over [`STALL_WINDOW`] iterations below which the energy has stalled.
pub const STALL_RELATIVE: Real = 1e-14;

/// The text of the stalled-energy termination reason.
pub const STALLED: &str = "energy stalled at rounding level";

/// Wraps a solver: stops when the gradient norm is at most `tolerance` and
/// records every iteration into a shared [`History`].
#[derive(Clone)]
pub struct Converging<S> {
    /// The wrapped solver.
    pub inner: S,
    /// Gradient-norm tolerance.
    pub tolerance: Real,
    /// Shared record of the run (kept when the run fails).
    pub history: Arc<Mutex<History>>,
}

type NcgState = IterState<DVector<Real>, DVector<Real>, (), (), (), Real>;

impl<S> Converging<S> {
    /// Whether the recorded energy fell by less than `STALL_RELATIVE · E` over the last window.
    fn stalled(&self) -> bool {
        let Ok(h) = self.history.lock() else {
            return false;
        };
        let e = &h.energies;
        e.len() > STALL_WINDOW && {
            let last = e[e.len() - 1];
            e[e.len() - 1 - STALL_WINDOW] - last <= STALL_RELATIVE * last.abs()
        }
    }

    fn record(&self, state: &NcgState) {
        if let Ok(mut h) = self.history.lock() {
            h.energies.push(state.get_cost());
            let g = state.get_gradient().map_or(Real::NAN, |g| g.norm());
            h.gradient_norms.push(g);
            h.last = state.get_param().cloned();
        }
    }
}

impl<O, S> Solver<O, NcgState> for Converging<S>
where
    S: Solver<O, NcgState>,
{
    fn name(&self) -> &str {
        "NCG with a gradient tolerance"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: NcgState,
    ) -> Result<(NcgState, Option<KV>), ArgminError> {
        let (state, kv) = self.inner.init(problem, state)?;
        self.record(&state);
        Ok((state, kv))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: NcgState,
    ) -> Result<(NcgState, Option<KV>), ArgminError> {
        let (state, kv) = self.inner.next_iter(problem, state)?;
        self.record(&state);
        Ok((state, kv))
    }

    fn terminate(&mut self, state: &NcgState) -> TerminationStatus {
        match state.get_gradient() {
            Some(g) if g.norm() <= self.tolerance => {
                TerminationStatus::Terminated(TerminationReason::SolverConverged)
            }
            _ if self.stalled() => {
                TerminationStatus::Terminated(TerminationReason::SolverExit(STALLED.into()))
            }
            _ => self.inner.terminate(state),
        }
    }
}

//! Minimisation of a [`SpringEnergy`] over the free vertices with argmin's
//! nonlinear conjugate gradient (Polak-Ribière+, Moré-Thuente line search,
//! restarts every 50 iterations or when successive gradients lose
//! orthogonality), stopping on a small gradient or a stalled energy.
//!
//! The solver works in scaled variables `x_v = x0_v + s_v y_v` with
//! `s_v = 1 / √h_v`, `h_v` the Gauss-Newton diagonal at the start (`2 k_l`
//! per edge at `v`, `2 k / |u|²` per joint leg `u` at `v`): a Jacobi
//! preconditioner by change of variables, so the line search's first trial
//! step of 1 is of the right size. The energy is unchanged.

use std::sync::{Arc, Mutex};

use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{
    CostFunction, Error as ArgminError, Executor, Gradient, IterState, KV, Problem, Solver, State,
    TerminationReason, TerminationStatus,
};
use argmin::solver::conjugategradient::NonlinearConjugateGradient;
use argmin::solver::conjugategradient::beta::PolakRibierePlus;
use argmin::solver::linesearch::MoreThuenteLineSearch;
use nalgebra::DVector;

use crate::error::{Error, Result};
use crate::linalg::{LeastSquares, LmParams, LmTimings, levenberg_marquardt};
use crate::math::{Point3, Real};

use super::SurfaceFineTuneParams;
use super::method::FinetuneMethod;
use super::surface_energy::SpringEnergy;
use super::surface_gauss_newton::SurfacePointProblem;

/// Positions and history of one minimisation.
pub struct Minimised {
    /// Final positions (all vertices).
    pub positions: Vec<Point3>,
    /// Energy before the first iteration and after each iteration.
    pub energies: Vec<Real>,
    /// Gradient norm after each iteration.
    pub gradient_norms: Vec<Real>,
    /// Iterations done.
    pub iterations: u64,
    /// Why it stopped.
    pub termination: String,
    /// Phase timings of Levenberg-Marquardt (zero for nonlinear CG).
    pub timings: LmTimings,
}

type Param = DVector<Real>;
type St = IterState<Param, Param, (), (), (), Real>;

struct Springs<'a> {
    energy: &'a SpringEnergy,
    base: &'a [Point3],
    free: &'a [usize],
    scale: &'a [Real],
}

impl Springs<'_> {
    fn positions(&self, p: &Param) -> Vec<Point3> {
        let mut x = self.base.to_vec();
        for (k, &v) in self.free.iter().enumerate() {
            let s = self.scale[k];
            x[v] += nalgebra::Vector3::new(p[3 * k], p[3 * k + 1], p[3 * k + 2]) * s;
        }
        x
    }
}

impl CostFunction for Springs<'_> {
    type Param = Param;
    type Output = Real;
    fn cost(&self, p: &Param) -> std::result::Result<Real, ArgminError> {
        Ok(self.energy.energy(&self.positions(p)))
    }
}

impl Gradient for Springs<'_> {
    type Param = Param;
    type Gradient = Param;
    fn gradient(&self, p: &Param) -> std::result::Result<Param, ArgminError> {
        let (_, g) = self.energy.energy_and_gradient(&self.positions(p), true);
        Ok(DVector::from_iterator(
            3 * self.free.len(),
            self.free
                .iter()
                .zip(self.scale)
                .flat_map(|(&v, &s)| [g[v].x * s, g[v].y * s, g[v].z * s]),
        ))
    }
}

/// Iterations over which the relative energy decrease is measured.
const STALL_WINDOW: usize = 10;

/// NLCG with two extra stopping rules.
#[derive(Clone)]
struct Stopping<S> {
    inner: S,
    gradient_tolerance: Real,
    energy_tolerance: Real,
    history: Vec<Real>,
}

impl<O, S: Solver<O, St>> Solver<O, St> for Stopping<S> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: St,
    ) -> std::result::Result<(St, Option<KV>), ArgminError> {
        self.inner.init(problem, state)
    }
    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: St,
    ) -> std::result::Result<(St, Option<KV>), ArgminError> {
        self.inner.next_iter(problem, state)
    }
    fn terminate(&mut self, state: &St) -> TerminationStatus {
        let g = state.get_gradient().map_or(Real::INFINITY, |g| g.norm());
        if g <= self.gradient_tolerance {
            return TerminationStatus::Terminated(TerminationReason::SolverConverged);
        }
        let c = state.get_cost();
        self.history.push(c);
        let n = self.history.len();
        if n > STALL_WINDOW {
            let before = self.history[n - 1 - STALL_WINDOW];
            if before - c <= self.energy_tolerance * c.abs() {
                return TerminationStatus::Terminated(TerminationReason::SolverExit(format!(
                    "energy fell by less than {:e} (relative) over the last {STALL_WINDOW} iterations",
                    self.energy_tolerance
                )));
            }
        }
        TerminationStatus::NotTerminated
    }
}

/// Records the cost and parameters after every iteration.
#[derive(Clone, Default)]
struct Record(Arc<Mutex<History>>);

/// Costs, last parameters and gradient norms seen by [`Record`].
type History = (Vec<Real>, Option<Param>, Vec<Real>);

impl Observe<St> for Record {
    fn observe_iter(&mut self, state: &St, _kv: &KV) -> std::result::Result<(), ArgminError> {
        if let Ok(mut r) = self.0.lock() {
            r.0.push(state.get_cost());
            r.1 = state.get_param().cloned();
            r.2.push(state.get_gradient().map_or(Real::NAN, |g| g.norm()));
        }
        Ok(())
    }
}

/// Minimises `energy` from `x0`, moving only the vertices not `fixed`.
pub fn minimise(
    energy: &SpringEnergy,
    x0: &[Point3],
    fixed: &[bool],
    params: &SurfaceFineTuneParams,
) -> Result<Minimised> {
    let free: Vec<usize> = (0..x0.len()).filter(|&v| !fixed[v]).collect();
    let start = DVector::zeros(3 * free.len());
    let h = gauss_newton_diagonal(energy, x0);
    let scale: Vec<Real> = free
        .iter()
        .map(|&v| if h[v] > 0.0 { 1.0 / h[v].sqrt() } else { 1.0 })
        .collect();
    let problem = Springs {
        energy,
        base: x0,
        free: &free,
        scale: &scale,
    };
    let e0 = energy.energy(x0);
    if free.is_empty() || params.max_iters == 0 {
        return Ok(Minimised {
            positions: x0.to_vec(),
            energies: vec![e0],
            gradient_norms: Vec::new(),
            iterations: 0,
            termination: "nothing to do".into(),
            timings: LmTimings::default(),
        });
    }
    if params.method == FinetuneMethod::LevenbergMarquardt {
        let problem = SurfacePointProblem::new(energy, x0, &free, &scale);
        let lm = LmParams {
            gradient_tolerance: params.gradient_tolerance,
            max_iterations: params.max_iters,
            stall_window: STALL_WINDOW,
            stall_relative: params.energy_tolerance,
            refinement_iterations: params.refinement_iterations,
        };
        let run = levenberg_marquardt(&problem, &vec![0.0; problem.num_vars()], &lm);
        return Ok(Minimised {
            positions: problem.positions(&run.z),
            energies: run.energies,
            gradient_norms: run.gradient_norms,
            iterations: run.iterations,
            termination: run.termination,
            timings: run.timings,
        });
    }
    let linesearch = MoreThuenteLineSearch::new()
        .with_c(1e-4, 0.1)
        .map_err(|e| Error::input(e.to_string()))?;
    let nlcg = NonlinearConjugateGradient::new(linesearch, PolakRibierePlus::new())
        .restart_iters(50)
        .restart_orthogonality(0.1);
    let solver = Stopping {
        inner: nlcg,
        gradient_tolerance: params.gradient_tolerance,
        energy_tolerance: params.energy_tolerance,
        history: Vec::new(),
    };
    let record = Record::default();
    let run = Executor::new(problem, solver)
        .configure(|s| s.param(start.clone()).max_iters(params.max_iters))
        .add_observer(record.clone(), ObserverMode::Always)
        .run();
    let (mut energies, last, gradient_norms) = record
        .0
        .lock()
        .map(|r| (r.0.clone(), r.1.clone(), r.2.clone()))
        .unwrap_or_default();
    energies.insert(0, e0);
    let springs = Springs {
        energy,
        base: x0,
        free: &free,
        scale: &scale,
    };
    let (param, iterations, termination) = match run {
        Ok(res) => {
            let st = res.state();
            let p = st
                .get_best_param()
                .or(st.get_param())
                .cloned()
                .unwrap_or(start);
            let why = st
                .get_termination_reason()
                .map_or("unknown".to_string(), |r| r.text().to_string());
            (p, st.get_iter(), why)
        }
        // A failed line search near the minimum: keep the last accepted iterate.
        Err(e) => {
            let n = energies.len() as u64 - 1;
            (
                last.unwrap_or(start),
                n,
                format!("line search stopped: {e}"),
            )
        }
    };
    let positions = springs.positions(&param);
    Ok(Minimised {
        positions,
        energies,
        gradient_norms,
        iterations,
        termination,
        timings: LmTimings::default(),
    })
}

/// The Gauss-Newton diagonal `h_v` of the energy at `x` (one value per vertex).
fn gauss_newton_diagonal(energy: &SpringEnergy, x: &[Point3]) -> Vec<Real> {
    let mut h = vec![0.0; x.len()];
    for &[a, b] in &energy.edges {
        h[a as usize] += 2.0 * energy.k_l;
        h[b as usize] += 2.0 * energy.k_l;
    }
    for (j, &k) in energy.joints.iter().zip(&energy.joint_weights) {
        let lu = (x[j[1] as usize] - x[j[0] as usize]).norm_squared();
        let lw = (x[j[3] as usize] - x[j[2] as usize]).norm_squared();
        if lu > 0.0 {
            h[j[0] as usize] += 2.0 * k / lu;
            h[j[1] as usize] += 2.0 * k / lu;
        }
        if lw > 0.0 {
            h[j[2] as usize] += 2.0 * k / lw;
            h[j[3] as usize] += 2.0 * k / lw;
        }
    }
    h
}

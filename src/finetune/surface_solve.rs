//! Minimisation of a [`SpringEnergy`] over the free vertices with argmin's
//! nonlinear conjugate gradient (Polak-Ribière+, Moré-Thuente line search,
//! restarts every 50 iterations or when successive gradients lose
//! orthogonality), stopping on a small gradient or a stalled energy.

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
use crate::math::{Point3, Real};

use super::SurfaceFineTuneParams;
use super::surface_energy::SpringEnergy;

/// Positions and history of one minimisation.
pub struct Minimised {
    /// Final positions (all vertices).
    pub positions: Vec<Point3>,
    /// Energy before the first iteration and after each iteration.
    pub energies: Vec<Real>,
    /// Iterations done.
    pub iterations: u64,
    /// Why it stopped.
    pub termination: String,
}

type Param = DVector<Real>;
type St = IterState<Param, Param, (), (), (), Real>;

struct Springs<'a> {
    energy: &'a SpringEnergy,
    base: &'a [Point3],
    free: &'a [usize],
}

impl Springs<'_> {
    fn positions(&self, p: &Param) -> Vec<Point3> {
        let mut x = self.base.to_vec();
        for (k, &v) in self.free.iter().enumerate() {
            x[v] = Point3::new(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
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
            self.free.iter().flat_map(|&v| [g[v].x, g[v].y, g[v].z]),
        ))
    }
}

/// NLCG with two extra stopping rules.
#[derive(Clone)]
struct Stopping<S> {
    inner: S,
    gradient_tolerance: Real,
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
        let (c, prev) = (state.get_cost(), state.get_prev_cost());
        if state.get_iter() > 0 && (prev - c).abs() <= 1e-15 * c.abs().max(1e-30) {
            return TerminationStatus::Terminated(TerminationReason::SolverExit(
                "energy stalled".into(),
            ));
        }
        TerminationStatus::NotTerminated
    }
}

/// Records the cost and parameters after every iteration.
#[derive(Clone, Default)]
struct Record(Arc<Mutex<(Vec<Real>, Option<Param>)>>);

impl Observe<St> for Record {
    fn observe_iter(&mut self, state: &St, _kv: &KV) -> std::result::Result<(), ArgminError> {
        if let Ok(mut r) = self.0.lock() {
            r.0.push(state.get_cost());
            r.1 = state.get_param().cloned();
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
    let start = DVector::from_iterator(
        3 * free.len(),
        free.iter().flat_map(|&v| [x0[v].x, x0[v].y, x0[v].z]),
    );
    let problem = Springs {
        energy,
        base: x0,
        free: &free,
    };
    let e0 = energy.energy(x0);
    if free.is_empty() || params.max_iters == 0 {
        return Ok(Minimised {
            positions: x0.to_vec(),
            energies: vec![e0],
            iterations: 0,
            termination: "nothing to do".into(),
        });
    }
    let linesearch = MoreThuenteLineSearch::new()
        .with_c(1e-4, 0.1)
        .map_err(|e| Error::Input(e.to_string()))?;
    let nlcg = NonlinearConjugateGradient::new(linesearch, PolakRibierePlus::new())
        .restart_iters(50)
        .restart_orthogonality(0.1);
    let solver = Stopping {
        inner: nlcg,
        gradient_tolerance: params.gradient_tolerance,
    };
    let record = Record::default();
    let run = Executor::new(problem, solver)
        .configure(|s| s.param(start.clone()).max_iters(params.max_iters))
        .add_observer(record.clone(), ObserverMode::Always)
        .run();
    let (mut energies, last) = record
        .0
        .lock()
        .map(|r| (r.0.clone(), r.1.clone()))
        .unwrap_or_default();
    energies.insert(0, e0);
    let springs = Springs {
        energy,
        base: x0,
        free: &free,
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
        iterations,
        termination,
    })
}

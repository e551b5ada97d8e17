//! Levenberg-Marquardt minimisation of a sum of squares `E = Σ_k r_k(z)²`
//! with a sparse Gauss-Newton matrix, the default solver of fine tuning
//! (`finetune`'s curve and surface energies).
//!
//! Energies (13) and (14) of the fine-tuning paper are sums of squared
//! spring residuals (`√k_l (l − l_opt)`, `√k_a (θ − θ_opt)`), so with
//! `g = 2 Jᵀ r` and `H = 2 Jᵀ J` each step solves
//! `(H + λ D) δ = −g`, `D = diag(H)` (Marquardt 1963; floored at `1e-12`
//! of its largest entry so that it is positive definite), by the sparse
//! 3 × 3-block Cholesky of `block_cholesky` (pattern and ordering computed
//! once).
//! After the first factorisation a step is first solved by conjugate
//! gradients preconditioned with the last factor (`refined_step`,
//! [`LmParams::refinement_iterations`]), only as accurately as the
//! gradient asks for (an inexact Newton step, [`FORCING_MAX`]), and factored
//! afresh only if that does not converge: on the benchmark surface one
//! factorisation and about 5 CG iterations per later step instead of four
//! factorisations. Rows
//! sharing their variables (an angle and its curvature rows) have their
//! `JᵀJ` summed densely before it is scattered into the factor's slots;
//! [`LmTimings`] records where the time goes. A step
//! is accepted only if it lowers `E`, so the recorded energies never rise;
//! `λ` starts at [`LAMBDA_START`] (nearly a Gauss-Newton step: `D` makes
//! it relative) and follows Nielsen's rule (Madsen, Nielsen, Tingleff,
//! *Methods for non-linear least squares problems*, 2004, §3.2): on
//! acceptance `λ ← λ max(1/10, 1 − (2ρ − 1)³)` with `ρ` the ratio of actual
//! to predicted decrease (Nielsen bounds the factor by 1/3; 1/10 lets good
//! steps approach Gauss-Newton sooner: 4 instead of 11 iterations on the
//! benchmark surface, 6 instead of 15 on the benchmark curve), on rejection
//! `λ ← λ ν`, `ν ← 2ν`.
//!
//! It stops when the problem's gradient norm is at most the tolerance, when
//! the energy fell too little over a window of iterations (optional), when
//! the predicted decrease of a rejected step is below rounding level
//! (`1e-14 E`: the energy has stalled), or at the iteration limit. Compared
//! with nonlinear CG, which needs thousands of iterations on these
//! ill-conditioned spring systems, it needs tens.

use std::time::Instant;

use crate::math::Real;

use super::block_cholesky::{CholeskyPattern, join_if};
use super::refined_step::preconditioned_solution;

/// Problems with at least this many runs of rows assemble `H` on two threads.
const PARALLEL_RUNS: usize = 2048;

/// Residual values and their sparse gradients, row by row.
#[derive(Clone, Debug, Default)]
pub struct Residuals {
    /// `r_k`.
    pub values: Vec<Real>,
    /// Start of row `k`'s entries in `vars` / `grads` (one more than rows).
    pub start: Vec<usize>,
    /// Variable of each entry (repeats within a row are allowed and add up).
    pub vars: Vec<usize>,
    /// `∂r_k/∂z_var` of each entry.
    pub grads: Vec<Real>,
}

impl Residuals {
    /// Empties the rows, keeping the allocations.
    pub fn clear(&mut self) {
        self.values.clear();
        self.vars.clear();
        self.grads.clear();
        self.start.clear();
        self.start.push(0);
    }

    /// Appends residual `r` with gradient entries `(var, ∂r/∂z_var)`.
    pub fn push(&mut self, r: Real, entries: impl IntoIterator<Item = (usize, Real)>) {
        for (v, g) in entries {
            self.vars.push(v);
            self.grads.push(g);
        }
        self.values.push(r);
        self.start.push(self.vars.len());
    }
}

/// A sum-of-squares problem. Every call of [`residuals`](Self::residuals)
/// must produce the same rows with the same variables (zero gradients
/// included), so that the sparsity pattern is fixed.
pub trait LeastSquares {
    /// Number of variables.
    fn num_vars(&self) -> usize;
    /// A node per variable: variables of one node are ordered together.
    fn nodes(&self) -> Vec<usize>;
    /// `E(z) = Σ r_k²`.
    fn energy(&self, z: &[Real]) -> Real;
    /// The residuals and their gradients at `z`, into `out`, which is empty
    /// or holds this problem's rows from an earlier call (an implementation
    /// may keep their variables and rewrite only values and gradients).
    fn residuals(&self, z: &[Real], out: &mut Residuals);
    /// The gradient norm compared with the tolerance, given `∇E(z)`; by
    /// default `|∇E|`.
    fn gradient_norm(&self, z: &[Real], gradient: &[Real]) -> Real {
        let _ = z;
        gradient.iter().map(|g| g * g).sum::<Real>().sqrt()
    }
}

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmParams {
    /// Stop when the problem's gradient norm is at most this.
    pub gradient_tolerance: Real,
    /// Iteration limit (accepted steps).
    pub max_iterations: u64,
    /// Stop when `E` fell by less than `stall_relative · E` over the last
    /// `stall_window` iterations (0 disables the rule).
    pub stall_window: usize,
    /// See `stall_window`.
    pub stall_relative: Real,
    /// Conjugate-gradient iterations allowed to solve a trial step with the
    /// previous factorisation as preconditioner (`refined_step`) before
    /// factoring afresh; 0 factors every trial step. Suggested:
    /// [`REFINEMENT_ITERATIONS`].
    pub refinement_iterations: usize,
}

/// The suggested [`LmParams::refinement_iterations`]: 15. One iteration
/// costs a product with `H` and a triangular solve pair, about a twentieth
/// to a thirtieth of a numeric factorisation on the benchmark surface,
/// whose steps after the first needed 10–11 iterations when solved to
/// `1e-10` (with a limit of 10 the second step missed by one and was
/// factored afresh) and need 3–6 with the forcing term [`FORCING_MAX`].
pub const REFINEMENT_ITERATIONS: usize = 15;

/// The largest forcing term of a step solved by conjugate gradients: the
/// step is solved to `|(H + λD) δ + g| ≤ η |g|` with `η = min(FORCING_MAX,
/// |∇E| / |∇E₀|)` (floored at [`RELATIVE_RESIDUAL`](super::RELATIVE_RESIDUAL)),
/// an inexact Newton step whose forcing term falls with the gradient, which
/// keeps Gauss-Newton's fast final convergence (Dembo, Eisenstat and
/// Steihaug, *Inexact Newton methods*, SIAM J. Numer. Anal. 19, 1982:
/// `η = O(|∇E|)` converges quadratically near the solution). On the
/// benchmark surface: 14 conjugate-gradient iterations instead of 32 for the
/// three later steps, the same 4 Levenberg-Marquardt iterations and the
/// same final energy.
pub const FORCING_MAX: Real = 1e-2;

/// The starting damping `λ` (relative to `diag(H)`): `1e-6`. Starting at
/// Nielsen's `1e-3` cost 11 iterations instead of 4 on the benchmark
/// surface; a first step that is too long is rejected and `λ` grows.
pub const LAMBDA_START: Real = 1e-6;

/// The termination text when the energy can no longer resolve progress.
pub const LM_STALLED: &str = "energy stalled at rounding level";
/// The termination text when the gradient tolerance is reached.
pub const LM_CONVERGED: &str = "gradient below tolerance";

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct LmRun {
    /// The last accepted variables.
    pub z: Vec<Real>,
    /// `E` at the start and after every accepted step.
    pub energies: Vec<Real>,
    /// The gradient norm at the same points.
    pub gradient_norms: Vec<Real>,
    /// Accepted steps.
    pub iterations: u64,
    /// Gradient tolerance reached or energy stalled at rounding level.
    pub converged: bool,
    /// Why it stopped.
    pub termination: String,
    /// Where the time went.
    pub timings: LmTimings,
}

/// Seconds spent in each phase of a [`levenberg_marquardt`] run, and the
/// number of factorisations (one per accepted or rejected trial step).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct LmTimings {
    /// Ordering and symbolic analysis ([`CholeskyPattern::new`]), once per run.
    pub symbolic: f64,
    /// Residuals and their gradients (`J`), once per accepted step.
    pub residuals: f64,
    /// `E`, `g = 2 Jᵀ r` and `H = 2 JᵀJ` into the factor's slots.
    pub assembly: f64,
    /// Numeric factorisations of `H + λ D`.
    pub factor: f64,
    /// Triangular solves.
    pub solve: f64,
    /// Energy evaluations of trial points.
    pub energy: f64,
    /// Preconditioned conjugate gradients with an earlier factor
    /// (converged or not).
    pub refine: f64,
    /// Factorisations done.
    pub factorizations: u64,
    /// Trial steps solved from an earlier factor, and the conjugate-gradient
    /// iterations they took (failed attempts included).
    pub refined: [u64; 2],
}

/// Minimises `problem` from `z0`.
pub fn levenberg_marquardt<P: LeastSquares>(problem: &P, z0: &[Real], params: &LmParams) -> LmRun {
    let n = problem.num_vars();
    let mut z = z0.to_vec();
    let mut rows = Residuals::default();
    let mut timings = LmTimings::default();
    let mut clock = Instant::now();
    problem.residuals(&z, &mut rows);
    timings.residuals += lap(&mut clock);
    // Rows with the same variables as the row before share its slots (the
    // curvature rows follow their angle row): runs `(first row, end, first
    // slot, whether a variable repeats)`, whose `JᵀJ` is summed densely
    // before it is scattered.
    let mut groups: Vec<&[usize]> = Vec::new();
    let mut runs: Vec<(usize, usize, usize, bool)> = Vec::new();
    let mut total = 0;
    for k in 0..rows.values.len() {
        let vars = &rows.vars[rows.start[k]..rows.start[k + 1]];
        match runs.last_mut() {
            Some(run) if groups.last() == Some(&vars) => run.1 = k + 1,
            _ => {
                let repeats = vars
                    .iter()
                    .enumerate()
                    .any(|(p, a)| vars[p + 1..].contains(a));
                runs.push((k, k + 1, total, repeats));
                total += vars.len() * (vars.len() + 1) / 2;
                groups.push(vars);
            }
        }
    }
    let (pattern, slots) = CholeskyPattern::new(n, &problem.nodes(), &groups);
    timings.symbolic += lap(&mut clock);
    let diag_slots = &slots[slots.len() - n..];
    // H and g, and the second thread's arrays (empty when serial).
    let parallel = runs.len() >= PARALLEL_RUNS;
    let (mut h, mut h2) = (vec![0.0; pattern.num_values()], Vec::new());
    let (mut g, mut g2) = (vec![0.0; n], Vec::new());
    if parallel {
        h2 = h.clone();
        g2 = g.clone();
    }
    let (first_half, second_half) =
        runs.split_at(if parallel { runs.len() / 2 } else { runs.len() });
    let mut run = LmRun {
        z: Vec::new(),
        energies: Vec::new(),
        gradient_norms: Vec::new(),
        iterations: 0,
        converged: false,
        termination: String::new(),
        timings: LmTimings::default(),
    };
    drop(groups);
    let (mut lambda, mut nu) = (LAMBDA_START, 2.0);
    // The last numeric factor, the preconditioner of later steps.
    let mut previous = None;
    loop {
        // E, g = 2 Jᵀr and H = 2 JᵀJ at z: the two halves of the runs on
        // two threads, the second into its own arrays, added after.
        let (e1, e2) = join_if(
            parallel,
            || accumulate(&rows, first_half, &slots, &mut h, &mut g),
            || accumulate(&rows, second_half, &slots, &mut h2, &mut g2),
        );
        let e = e1 + e2;
        h.iter_mut().zip(&h2).for_each(|(a, b)| *a += b);
        g.iter_mut().zip(&g2).for_each(|(a, b)| *a += b);
        let gnorm = problem.gradient_norm(&z, &g);
        timings.assembly += lap(&mut clock);
        run.energies.push(e);
        run.gradient_norms.push(gnorm);
        if gnorm <= params.gradient_tolerance {
            run.converged = true;
            run.termination = LM_CONVERGED.into();
            break;
        }
        let n_e = run.energies.len();
        if params.stall_window > 0
            && n_e > params.stall_window
            && run.energies[n_e - 1 - params.stall_window] - e <= params.stall_relative * e.abs()
        {
            run.termination = format!(
                "energy fell by less than {:e} (relative) over the last {} iterations",
                params.stall_relative, params.stall_window
            );
            break;
        }
        if run.iterations >= params.max_iterations {
            run.termination = "iteration limit".into();
            break;
        }
        let dmax = diag_slots.iter().map(|&s| h[s]).fold(0.0, Real::max);
        let floor = 1e-12 * dmax.max(Real::MIN_POSITIVE);
        let d: Vec<Real> = diag_slots.iter().map(|&s| h[s].max(floor)).collect();
        let accepted = loop {
            let mut a = h.clone();
            for (i, &s) in diag_slots.iter().enumerate() {
                a[s] += lambda * d[i];
            }
            let neg: Vec<Real> = g.iter().map(|v| -v).collect();
            let mut step = None;
            if let Some(f) = previous
                .as_ref()
                .filter(|_| params.refinement_iterations > 0)
            {
                let forcing = (gnorm / run.gradient_norms[0]).min(FORCING_MAX);
                let (x, its) = preconditioned_solution(
                    &pattern,
                    &a,
                    f,
                    &neg,
                    forcing,
                    params.refinement_iterations,
                );
                timings.refine += lap(&mut clock);
                timings.refined[1] += its as u64;
                timings.refined[0] += u64::from(x.is_some());
                step = x;
            }
            if step.is_none() {
                previous = pattern.factor(&a);
                timings.factor += lap(&mut clock);
                timings.factorizations += 1;
                step = previous.as_ref().map(|f| f.solution(&neg));
                timings.solve += lap(&mut clock);
            }
            let Some(step) = step.filter(|x| x.iter().all(|v| v.is_finite())) else {
                lambda *= nu;
                nu *= 2.0;
                if lambda > 1e20 {
                    break None;
                }
                continue;
            };
            let trial: Vec<Real> = z.iter().zip(&step).map(|(a, b)| a + b).collect();
            let e_new = problem.energy(&trial);
            timings.energy += lap(&mut clock);
            let g_step: Real = g.iter().zip(&step).map(|(a, b)| a * b).sum();
            let damp: Real = step.iter().zip(&d).map(|(x, di)| di * x * x).sum();
            let predicted = 0.5 * (lambda * damp - g_step);
            if e_new.is_finite() && e_new < e && predicted > 0.0 {
                let rho = (e - e_new) / predicted;
                lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(0.1);
                nu = 2.0;
                break Some(trial);
            }
            if predicted.is_nan() || predicted <= 1e-14 * e.abs() {
                run.converged = true;
                run.termination = LM_STALLED.into();
                break None;
            }
            lambda *= nu;
            nu *= 2.0;
            if lambda > 1e20 {
                break None;
            }
        };
        let Some(trial) = accepted else {
            if run.termination.is_empty() {
                run.termination = "no step lowers the energy".into();
            }
            break;
        };
        z = trial;
        run.iterations += 1;
        clock = Instant::now();
        problem.residuals(&z, &mut rows);
        timings.residuals += lap(&mut clock);
    }
    run.z = z;
    run.timings = timings;
    run
}

/// Sets `h` to `Σ 2 JₖᵀJₖ` (in the factor's `slots`) and `g` to `Σ 2 rₖ Jₖ`
/// over the rows of `runs` (each `(first row, end, first slot, repeats)`: rows with
/// the same variables, whose `JᵀJ` is summed densely before it is
/// scattered); returns `Σ rₖ²`.
fn accumulate(
    rows: &Residuals,
    runs: &[(usize, usize, usize, bool)],
    slots: &[usize],
    h: &mut [Real],
    g: &mut [Real],
) -> Real {
    h.iter_mut().for_each(|v| *v = 0.0);
    g.iter_mut().for_each(|v| *v = 0.0);
    let mut local: Vec<Real> = Vec::new();
    let mut e = 0.0;
    for &(first, end, first_slot, repeats) in runs {
        let vars = &rows.vars[rows.start[first]..rows.start[first + 1]];
        let m = vars.len();
        local.clear();
        local.resize(m * (m + 1) / 2, 0.0);
        let mut used = false;
        for k in first..end {
            let r = rows.values[k];
            e += r * r;
            let grads = &rows.grads[rows.start[k]..rows.start[k + 1]];
            if r == 0.0 && grads.iter().all(|&x| x == 0.0) {
                // An unused curvature row: nothing to add.
                continue;
            }
            used = true;
            let mut t = 0;
            for (p, (&a, &ga)) in vars.iter().zip(grads).enumerate() {
                g[a] += 2.0 * r * ga;
                let tail = &grads[p..];
                for (l, &gb) in local[t..t + tail.len()].iter_mut().zip(tail) {
                    *l += ga * gb;
                }
                t += tail.len();
            }
        }
        if !used {
            continue;
        }
        let run_slots = &slots[first_slot..first_slot + local.len()];
        if repeats {
            let mut t = 0;
            for (p, &a) in vars.iter().enumerate() {
                for (q, &b) in vars.iter().enumerate().skip(p) {
                    // A variable repeated in a row: its cross term stands for both orders.
                    let twice = if q != p && a == b { 2.0 } else { 1.0 };
                    h[run_slots[t]] += 2.0 * local[t] * twice;
                    t += 1;
                }
            }
        } else {
            for (&s, &l) in run_slots.iter().zip(&local) {
                h[s] += 2.0 * l;
            }
        }
    }
    e
}

/// Seconds since `clock`, restarting it.
fn lap(clock: &mut Instant) -> f64 {
    let now = Instant::now();
    let t = now.duration_since(*clock).as_secs_f64();
    *clock = now;
    t
}

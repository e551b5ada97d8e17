//! Levenberg-Marquardt minimisation of a sum of squares `E = Σ_k r_k(z)²`
//! with a sparse Gauss-Newton matrix, the default solver of fine tuning.
//!
//! Energies (13) and (14) of the fine-tuning paper are sums of squared
//! spring residuals (`√k_l (l − l_opt)`, `√k_a (θ − θ_opt)`), so with
//! `g = 2 Jᵀ r` and `H = 2 Jᵀ J` each step solves
//! `(H + λ D) δ = −g`, `D = diag(H)` (Marquardt 1963; floored at `1e-12`
//! of its largest entry so that it is positive definite), by the sparse
//! Cholesky of `sparse_cholesky` (pattern and ordering computed once). A step
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

use crate::math::Real;

use super::sparse_cholesky::CholeskyPattern;

/// Which minimiser fine tuning uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum FinetuneMethod {
    /// Levenberg-Marquardt on the sparse Gauss-Newton matrix (this module):
    /// tens of iterations. The default.
    #[default]
    LevenbergMarquardt,
    /// argmin's nonlinear conjugate gradient (Polak-Ribière+, Moré-Thuente
    /// line search), the method issue 8 named: thousands of iterations on
    /// the same problems.
    NonlinearCg,
}

impl std::str::FromStr for FinetuneMethod {
    type Err = crate::error::Error;
    /// `lm` or `ncg`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "lm" => Ok(FinetuneMethod::LevenbergMarquardt),
            "ncg" => Ok(FinetuneMethod::NonlinearCg),
            _ => Err(crate::error::Error::Input(format!(
                "unknown method {s:?}: expected lm or ncg"
            ))),
        }
    }
}

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
    /// The residuals and their gradients at `z`, into `out` (cleared first).
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
}

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
}

/// Minimises `problem` from `z0`.
pub fn levenberg_marquardt<P: LeastSquares>(problem: &P, z0: &[Real], params: &LmParams) -> LmRun {
    let n = problem.num_vars();
    let mut z = z0.to_vec();
    let mut rows = Residuals::default();
    problem.residuals(&z, &mut rows);
    // Rows with the same variables as the row before share its slots (the
    // curvature rows follow their angle row).
    let mut groups: Vec<&[usize]> = Vec::new();
    let mut row_slot = Vec::with_capacity(rows.values.len());
    let mut total = 0;
    for k in 0..rows.values.len() {
        let vars = &rows.vars[rows.start[k]..rows.start[k + 1]];
        if groups.last() == Some(&vars) {
            row_slot.push(row_slot[k - 1]);
        } else {
            row_slot.push(total);
            total += vars.len() * (vars.len() + 1) / 2;
            groups.push(vars);
        }
    }
    let (pattern, slots) = CholeskyPattern::new(n, &problem.nodes(), &groups);
    let diag_slots = &slots[slots.len() - n..];
    let mut h = vec![0.0; pattern.num_values()];
    let mut g = vec![0.0; n];
    let mut run = LmRun {
        z: Vec::new(),
        energies: Vec::new(),
        gradient_norms: Vec::new(),
        iterations: 0,
        converged: false,
        termination: String::new(),
    };
    drop(groups);
    let (mut lambda, mut nu) = (LAMBDA_START, 2.0);
    loop {
        // E, g = 2 Jᵀr and H = 2 JᵀJ at z.
        h.iter_mut().for_each(|v| *v = 0.0);
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut e = 0.0;
        for (k, &first_slot) in row_slot.iter().enumerate() {
            let (r, range) = (rows.values[k], rows.start[k]..rows.start[k + 1]);
            let mut s = first_slot;
            e += r * r;
            let (vars, grads) = (&rows.vars[range.clone()], &rows.grads[range]);
            if r == 0.0 && grads.iter().all(|&x| x == 0.0) {
                // An unused curvature row: nothing to add.
                continue;
            }
            for (p, (&a, &ga)) in vars.iter().zip(grads).enumerate() {
                g[a] += 2.0 * r * ga;
                for (q, (&b, &gb)) in vars.iter().zip(grads).enumerate().skip(p) {
                    // A variable repeated in a row: its cross term stands for both orders.
                    let twice = if q != p && a == b { 2.0 } else { 1.0 };
                    h[slots[s]] += 2.0 * ga * gb * twice;
                    s += 1;
                }
            }
        }
        let gnorm = problem.gradient_norm(&z, &g);
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
            let step = pattern.factor(&a).map(|f| f.solution(&neg));
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
        problem.residuals(&z, &mut rows);
    }
    run.z = z;
    run
}

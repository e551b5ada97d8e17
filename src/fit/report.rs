//! What a fit did: per level, the size of the model, the work and the error.

use serde::Serialize;

use super::ToleranceStat;
use crate::math::Real;

/// Statistics of data-to-surface distances, in absolute units and in % of the
/// object's diameter (the data's bounding-box diagonal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Largest distance (the paper's error).
    pub max: Real,
    /// Mean distance.
    pub mean: Real,
    /// Root mean square distance.
    pub rms: Real,
    /// 95th percentile (nearest rank).
    pub p95: Real,
    /// `max` in % of the diameter.
    pub max_pct: Real,
    /// `mean` in % of the diameter.
    pub mean_pct: Real,
    /// `rms` in % of the diameter.
    pub rms_pct: Real,
    /// `p95` in % of the diameter.
    pub p95_pct: Real,
}

impl ErrorStats {
    /// Statistics of `d` relative to `diameter`.
    pub fn new(d: &[Real], diameter: Real) -> ErrorStats {
        if d.is_empty() {
            return ErrorStats::default();
        }
        let n = d.len() as Real;
        let mut sorted = d.to_vec();
        let rank = ((0.95 * n).ceil() as usize).clamp(1, d.len()) - 1;
        // The element of that rank in sorted order, and those above it.
        let (_, &mut p95, above) = sorted.select_nth_unstable_by(rank, |a, b| a.total_cmp(b));
        let max = above
            .iter()
            .copied()
            .max_by(|a, b| a.total_cmp(b))
            .unwrap_or(p95);
        let mean = d.iter().sum::<Real>() / n;
        let rms = (d.iter().map(|x| x * x).sum::<Real>() / n).sqrt();
        let pct = |x: Real| 100.0 * x / diameter;
        ErrorStats {
            max,
            mean,
            rms,
            p95,
            max_pct: pct(max),
            mean_pct: pct(mean),
            rms_pct: pct(rms),
            p95_pct: pct(p95),
        }
    }

    /// The statistic `stat`, in % of the diameter.
    pub fn pct(&self, stat: ToleranceStat) -> Real {
        match stat {
            ToleranceStat::Max => self.max_pct,
            ToleranceStat::P95 => self.p95_pct,
            ToleranceStat::Rms => self.rms_pct,
            ToleranceStat::Mean => self.mean_pct,
        }
    }
}

/// One subdivision level of a fit.
#[derive(Clone, Debug, Serialize)]
pub struct LevelReport {
    /// Subdivision level above the initial control mesh.
    pub level: usize,
    /// Control points at this level.
    pub control_points: usize,
    /// Control faces at this level.
    pub faces: usize,
    /// Implicit steps taken.
    pub steps: usize,
    /// Conjugate-gradient iterations, summed over the steps.
    pub cg_iterations: usize,
    /// Wall time of the level, seconds.
    pub seconds: Real,
    /// Of `seconds`: building the level (patch table and seed tree,
    /// stiffness and damping, the system's pattern, surface samples).
    pub setup_seconds: Real,
    /// Of `seconds`: the distances of every data point at the end.
    pub error_seconds: Real,
    /// Seconds since the fit started, at the end of this level.
    pub elapsed: Real,
    /// Total energy before each step (data springs + stiffness).
    pub energy: Vec<Real>,
    /// Seconds since the fit started, at each entry of `energy`.
    pub step_elapsed: Vec<Real>,
    /// RMS data-to-surface distance (% of the diameter) at each entry of `energy`.
    pub step_rms_pct: Vec<Real>,
    /// 95th-percentile distance (% of the diameter) at each entry of `energy`.
    pub step_p95_pct: Vec<Real>,
    /// Data points the level's springs used (a subsample on coarse levels,
    /// see [`FitParams::points_per_control_point`](super::FitParams)).
    pub points_used: usize,
    /// Distances from all data points to the surface at the end of the level.
    pub error: ErrorStats,
    /// The same distances of the points kept in the springs (without the
    /// outliers left out, [`FitReport::outliers`]): the stop rules and the
    /// comparisons between fits of a level judge these, as a few percent of
    /// outliers would otherwise decide the 95th percentile.
    pub kept_error: ErrorStats,
    /// Fraction of data points whose robust weight is zero (rejected
    /// outliers; always 0 with Huber's kernel, the default, which rejects
    /// none: the outliers it would see are left out before the fit, see
    /// [`FitReport::outliers`]).
    pub rejected: Real,
    /// How this level came from the previous one: `initial`, `uniform`,
    /// `adaptive: F of N faces split`, or `uniform, after an adaptive level
    /// that fitted worse than its parent` (see
    /// [`Refinement::Adaptive`](super::Refinement)).
    pub refinement: String,
}

/// What the untangling after the last level did. The levels' error
/// statistics were measured before it; the control points it moved are
/// few, and `largest_move` bounds how far any moved.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Untangling {
    /// Self-intersecting tessellation pairs before it (at
    /// [`CHECK_RATE`](super::quality::CHECK_RATE)).
    pub pairs_before: usize,
    /// Smoothing rounds tried (the last one is undone when it did not
    /// lower the pairs).
    pub rounds: usize,
    /// Control points moved.
    pub moved_control_points: usize,
    /// The largest move of a control point (length units).
    pub largest_move: Real,
}

/// The whole fit.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// Number of data points.
    pub points: usize,
    /// The data's bounding-box diagonal (the object's diameter).
    pub diameter: Real,
    /// The estimated noise σ̃ along the normal (length units;
    /// [`crate::fit::init::outliers::Screening::noise`], 0 when unknown).
    pub noise: Real,
    /// Points left out of the springs as outliers
    /// ([`FitParams::drop_outliers`](super::FitParams)).
    pub outliers: usize,
    /// Per level, in order.
    pub levels: Vec<LevelReport>,
    /// True when the tolerance was met.
    pub converged: bool,
    /// Why the fit stopped.
    pub stop_reason: String,
    /// The untangling after the last level
    /// ([`FitParams::final_untangle_rounds`](super::FitParams::final_untangle_rounds)).
    pub final_untangling: Untangling,
    /// Total wall time, seconds.
    pub seconds: Real,
    /// What the result itself shows: surface far from the data, points far
    /// from the surface, folds ([`super::quality`]).
    pub quality: super::quality::FitQuality,
}

//! The rules of the multilevel loop that the point-cloud fit and the
//! volume recovery share (Qin, Mandal, Vemuri 1998, §6: the model settles
//! at a level, and is subdivided while its error is above the tolerance).

use crate::math::Real;

/// Whether a run stops after `level`, and why: `met` is the reason when
/// the level meets the driver's tolerance (the run has converged); else the
/// run stops at `max_level`, or when `gain` (the level's error measure and
/// its parent's, `None` when the rule does not apply) shows a fall by less
/// than `min_gain` of the parent's — a finer level would gain little.
/// `measure` names the error measure in that reason. `None`: go on.
pub(crate) fn stop_after_level(
    level: usize,
    met: Option<String>,
    max_level: usize,
    gain: Option<(Real, Real)>,
    min_gain: Real,
    measure: &str,
) -> Option<(bool, String)> {
    if let Some(reason) = met {
        return Some((true, reason));
    }
    if level >= max_level {
        return Some((
            false,
            format!("maximum level {level} reached above the tolerance"),
        ));
    }
    match gain {
        Some((last, parent)) if last > (1.0 - min_gain) * parent => Some((
            false,
            format!(
                "level {level} lowered the {measure} by less than {:.0} %: a finer level would gain little",
                100.0 * min_gain
            ),
        )),
        _ => None,
    }
}

/// A level fitted worse than its parent: both its RMS and its 95th
/// percentile are above the parent's. The fit then refines the parent
/// uniformly instead of adaptively; the recovery returns the parent.
pub(crate) fn fitted_worse(last: (Real, Real), parent: (Real, Real)) -> bool {
    last.0 > parent.0 && last.1 > parent.1
}

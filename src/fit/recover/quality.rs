//! Whether a recovery's result can be trusted: no silent garbage.

use super::{RecoverParams, RecoverReport};
use crate::math::Real;

/// The 95th percentile of the offsets (voxels) above which a result is
/// poor, unless twice the tolerance is larger ([`poor_result`]).
pub const POOR_OFFSET_VOXELS: Real = 1.0;

/// Why the result of a recovery is poor, one sentence each; empty when it
/// is not. A result is poor when the returned surface leaves the volume's
/// (padded) box by more than a voxel anywhere, when more than
/// `params.max_unresolved` of it found no boundary within its search range
/// (the "unresolved" share: such samples follow the thin plate, not the
/// image), when the 95th percentile of its offsets from the boundary is
/// above [`POOR_OFFSET_VOXELS`] and twice the tolerance (the surface did not
/// find the boundary it was given: pleats over a thin sheet, spikes; every
/// result of the recovery bench and its check volumes ends at 0.5 voxel or
/// less, the two poor ones at 1.5 and 2.2), or when a finer level followed
/// the image worse than its parent (it is dropped, but the image disagrees
/// with the model somewhere).
pub fn poor_result(report: &RecoverReport, params: &RecoverParams) -> Vec<String> {
    let mut why = Vec::new();
    let Some(last) = report.levels.get(report.returned_level) else {
        why.push("no level was recovered".to_string());
        return why;
    };
    if last.outside_box > 0.0 {
        why.push(format!(
            "the surface leaves the volume's box ({:.0} of its {} samples more than 1 voxel outside at level {})",
            last.outside_box * last.samples as Real,
            last.samples,
            last.level
        ));
    }
    if last.unresolved > params.max_unresolved {
        why.push(format!(
            "{:.1} % of the surface found no boundary within ±{:.1} voxels at level {} (at most {:.0} % accepted)",
            100.0 * last.unresolved,
            last.search_voxels,
            last.level,
            100.0 * params.max_unresolved
        ));
    }
    let off = POOR_OFFSET_VOXELS.max(2.0 * params.tolerance_voxels);
    if last.offsets.p95 > off {
        why.push(format!(
            "the surface is off the boundary at level {}: the 95th percentile of its offsets is {:.2} voxels, above {off:.2} (twice the tolerance, at least {POOR_OFFSET_VOXELS})",
            last.level, last.offsets.p95
        ));
    }
    if let Some(worse) = report.levels.get(report.returned_level + 1) {
        why.push(format!(
            "level {} followed the image worse than level {} (RMS offset {:.3} > {:.3} voxels)",
            worse.level, last.level, worse.offsets.rms, last.offsets.rms
        ));
    }
    why
}

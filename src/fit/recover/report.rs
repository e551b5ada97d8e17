//! What a volume recovery did, per level and per stage.

use serde::Serialize;

use crate::fit::ErrorStats;
use crate::math::Real;

/// One level of a recovery.
#[derive(Clone, Debug, Serialize)]
pub struct RecoverLevel {
    /// Subdivision level above the initial cage.
    pub level: usize,
    /// Control points.
    pub control_points: usize,
    /// Control faces.
    pub faces: usize,
    /// Quadrature points (image samples) on the limit surface.
    pub samples: usize,
    /// Implicit steps taken.
    pub steps: usize,
    /// Conjugate-gradient iterations over all steps.
    pub cg_iterations: usize,
    /// Wall time of the level in seconds.
    pub seconds: Real,
    /// Energy after every step.
    pub energy: Vec<Real>,
    /// Offsets from the surface to the boundary found along the normals, in
    /// voxels (`*_pct` fields: % of the model's diameter), at the end of the level.
    pub offsets: ErrorStats,
    /// Fraction of samples with no boundary within the search range.
    pub unresolved: Real,
    /// Search half-length used, in voxels.
    pub search_voxels: Real,
    /// Iso-surface points the two-sided forces used (0: none).
    pub boundary_points: usize,
    /// Share of them farther than the two-sided distance from the limit
    /// surface at the level's end.
    pub unmatched: Real,
    /// Fraction of samples more than 1 voxel outside the volume's sample
    /// box (the padded box, so a surface closed on the box faces is inside).
    pub outside_box: Real,
}

/// The whole recovery.
#[derive(Clone, Debug, Serialize)]
pub struct RecoverReport {
    /// Voxel size (smallest spacing) in world units.
    pub voxel: Real,
    /// Smoothing σ used, in world units.
    pub sigma: Real,
    /// Level inside/outside is decided at (the iso-value or Otsu's threshold).
    pub inside_level: Real,
    /// Seconds spent smoothing.
    pub smoothing_seconds: Real,
    /// Seconds spent on the edge potential (0 for an iso-surface).
    pub potential_seconds: Real,
    /// Per level (a level worse than its parent is listed, then dropped).
    pub levels: Vec<RecoverLevel>,
    /// Index in `levels` of the level whose control mesh is returned.
    pub returned_level: usize,
    /// Whether the tolerance was met.
    pub converged: bool,
    /// Why the recovery stopped.
    pub stop_reason: String,
    /// Wall time in seconds, smoothing included.
    pub seconds: Real,
}

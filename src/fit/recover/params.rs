//! Parameters of [`recover_shape`](super::recover_shape).

use crate::error::{Error, Result};
use crate::fit::Refinement;
use crate::forces::BoundaryModel;
use crate::math::Real;

/// Iso-value of the skin in CT, Hounsfield units (`--preset skin`): −500 HU.
///
/// On the Hounsfield scale air is −1000 HU and water 0 HU by definition;
/// skin and the soft tissue under it lie near 0 (fat −100). The level
/// half-way across a blurred step edge sits on the edge itself, so the
/// half-way level between air and soft tissue, −500 HU, puts the surface
/// on the skin whatever the scanner's blur. It lies inside the "Skin Tissue
/// (Adult)" threshold range of InVesalius's CT presets (−718 to −177 HU,
/// `invesalius/presets.py`, values from Materialise Mimics) and stays clear
/// of noise in the air around the head (tens of HU).
pub const SKIN_HU: Real = -500.0;

/// Iso-value of bone in CT, Hounsfield units (`--preset bone`): +300 HU.
///
/// Soft tissue and unenhanced blood are below about +100 HU; cortical bone
/// is +700 to +2000 HU and the skull's spongy bone +150 to +650
/// (InVesalius's CT presets: "Bone" from +226 HU, "Spongial Bone (Adult)"
/// +148 to +661). +300 HU is above soft tissue and most contrast-enhanced
/// vessels, below thin cortical bone whose value partial volume lowers, and
/// near the half-way level between soft tissue and spongy bone.
pub const BONE_HU: Real = 300.0;

/// Options of the volume recovery. Lengths in voxels are multiples of the
/// volume's smallest spacing.
#[derive(Clone, Debug, PartialEq)]
pub struct RecoverParams {
    /// What marks the boundary (default: the edge potential with
    /// `min_strength` 0.1; use [`BoundaryModel::Iso`] when the iso-value is known).
    pub boundary: BoundaryModel,
    /// Gaussian smoothing σ in world units (default `None`: a quarter of a
    /// voxel for an iso-surface, one voxel for edges). Blur moves a curved
    /// iso-surface inward by about `σ² κ / 2` (κ the mean curvature) and
    /// rounds edges and tips, so an iso-surface gets only enough to tame
    /// voxel noise; edges need more. The automatic cage is taken from the
    /// volume smoothed to at least half a voxel
    /// ([`CAGE_SIGMA_VOXELS`](super::CAGE_SIGMA_VOXELS)).
    pub sigma: Option<Real>,
    /// The object is brighter than its surroundings (default true).
    pub bright_inside: bool,
    /// Stop when the 95th percentile of the surface-to-boundary offsets is
    /// at or below this many voxels (default 0.5).
    pub tolerance_voxels: Real,
    /// Subdivision levels allowed above the initial cage (default 3).
    pub max_level: usize,
    /// Implicit steps per level at most (default 60; the level the seed
    /// grows at gets four times as many).
    pub max_steps: usize,
    /// A level has settled when the energy changes by less than this fraction
    /// between steps (default 1e-3), or by less than the energy of a uniform
    /// misfit of `settle_voxels`, or no control point moves by more than 1 %
    /// of a voxel.
    pub energy_tolerance: Real,
    /// See `energy_tolerance` (default 0.05 voxel: the energy's slow creep
    /// as the thin plate relaxes no longer moves the surface measurably).
    pub settle_voxels: Real,
    /// Stop subdividing when a level lowers the RMS offset by less than this
    /// fraction (default 0.1).
    pub min_level_gain: Real,
    /// Do not subdivide when the median control edge would be shorter than this
    /// many voxels (default 2).
    pub min_edge_voxels: Real,
    /// Half-length of the search along each normal, in voxels (default
    /// `None`: a third of the median control edge, clamped to 2 ..= 12 voxels).
    pub search_voxels: Option<Real>,
    /// Tension weight `λ_t` (as in [`FitParams`](crate::fit::FitParams); default 1e-5).
    pub tension: Real,
    /// Bending weight `λ_b` (default 1e-4).
    pub bending: Real,
    /// Damping over the time step relative to the image springs (default 0.05).
    pub damping: Real,
    /// Extra inflation pressure along the normal, relative to the image
    /// springs per unit area and in voxels (default 0; the search already
    /// pushes points with no boundary in range outward when they are inside).
    pub inflation: Real,
    /// Gauss-Legendre points per side of every level-1 piece (default 3).
    pub quadrature_order: usize,
    /// Total stiffness of the user-placed boundary points (the caudate
    /// experiment's springs, each point to its closest point of the limit
    /// surface) relative to the image springs, whose stiffness sums to 1
    /// (default 1; only used when points are given).
    pub points_weight: Real,
    /// Largest fraction of the surface allowed to find no boundary within
    /// its search range (default 0.1). A level above it ends the recovery
    /// (finer levels leave such samples to the thin plate, so they would
    /// not find it either), and [`poor_result`](super::poor_result) calls
    /// the result poor.
    pub max_unresolved: Real,
    /// Total stiffness of the two-sided forces relative to the image
    /// springs (default 2; 0 turns them off): the object's iso-surface
    /// points ([`ComponentCage::boundary`](super::ComponentCage::boundary))
    /// outside the limit surface and farther than
    /// [`two_sided_voxels`](Self::two_sided_voxels) from it each pull their
    /// closest point with a spring of `two_sided_weight / N` (`N` the
    /// points used), as the scan fit's data springs do, so a part the
    /// surface misses (a horn tip, a leg the cage lost) pulls it out at any
    /// level.
    pub two_sided_weight: Real,
    /// How far outside the limit surface an iso-surface point must lie to
    /// pull it, in voxels (default 0.5, the default tolerance).
    pub two_sided_voxels: Real,
    /// Largest share of the iso-surface points that pull (see
    /// [`two_sided_weight`](Self::two_sided_weight)) for the tolerance to
    /// count as met (default 0.05: the 95th percentile both ways).
    pub max_unmatched: Real,
    /// How a level above the tolerance is refined (default
    /// [`Refinement::Adaptive`]: the faces nearest a pulling iso-surface
    /// point, and while the 95th percentile of the offsets is above the
    /// tolerance the faces with a sample off by more than it, are split,
    /// the worst first, the others kept).
    pub refinement: Refinement,
    /// An adaptive level has at most this many times its parent's control
    /// points (default 2): the faces farthest off are split first
    /// (folded surfaces such as a brain's have far points everywhere, and
    /// splitting all their faces costs the memory of a uniform level).
    pub max_level_growth: Real,
    /// Adaptive levels stop adding control points at this share of the
    /// object's iso-surface points (the crossings of the iso-level on voxel
    /// edges, which are marching cubes' vertices; default 0.1): the surface
    /// keeps at least ten times fewer degrees of freedom than a voxel-level
    /// mesh, so refining cannot end up fitting the voxel noise.
    pub max_control_share: Real,
}

impl Default for RecoverParams {
    fn default() -> Self {
        RecoverParams {
            boundary: BoundaryModel::Edge { min_strength: 0.1 },
            sigma: None,
            bright_inside: true,
            tolerance_voxels: 0.5,
            max_level: 3,
            max_steps: 60,
            energy_tolerance: 1e-3,
            settle_voxels: 0.05,
            min_level_gain: 0.1,
            min_edge_voxels: 2.0,
            search_voxels: None,
            tension: 1e-5,
            bending: 1e-4,
            damping: 0.05,
            inflation: 0.0,
            quadrature_order: 3,
            points_weight: 1.0,
            max_unresolved: 0.1,
            two_sided_weight: 2.0,
            two_sided_voxels: 0.5,
            max_unmatched: 0.05,
            refinement: Refinement::Adaptive,
            max_level_growth: 2.0,
            max_control_share: 0.1,
        }
    }
}

impl RecoverParams {
    /// Checks every value; the error names the parameter.
    pub fn check(&self) -> Result<()> {
        let positive = |name: &str, v: Real| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::input(format!(
                    "{name} {v} must be a positive number"
                )))
            }
        };
        let non_negative = |name: &str, v: Real| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(Error::input(format!(
                    "{name} {v} must be a finite number ≥ 0"
                )))
            }
        };
        match self.boundary {
            BoundaryModel::Iso { value } if !value.is_finite() => {
                return Err(Error::non_finite(format!(
                    "iso-value {value} is not finite"
                )));
            }
            BoundaryModel::Edge { min_strength } if !(0.0..1.0).contains(&min_strength) => {
                return Err(Error::input(format!(
                    "edge strength {min_strength} must be in [0, 1)"
                )));
            }
            _ => {}
        }
        if let Some(s) = self.sigma {
            non_negative("sigma", s)?;
        }
        positive("tolerance", self.tolerance_voxels)?;
        if self.max_level > 6 {
            return Err(Error::input(format!(
                "max level {} is absurd: each level has four times the faces; at most 6",
                self.max_level
            )));
        }
        if self.max_steps == 0 || self.max_steps > 100_000 {
            return Err(Error::input(format!(
                "max steps {} must be between 1 and 100000",
                self.max_steps
            )));
        }
        positive("energy tolerance", self.energy_tolerance)?;
        non_negative("settle voxels", self.settle_voxels)?;
        non_negative("min level gain", self.min_level_gain)?;
        positive("min edge", self.min_edge_voxels)?;
        if let Some(s) = self.search_voxels {
            positive("search range", s)?;
        }
        non_negative("tension", self.tension)?;
        non_negative("bending", self.bending)?;
        positive("damping", self.damping)?;
        non_negative("points weight", self.points_weight)?;
        non_negative("two-sided weight", self.two_sided_weight)?;
        positive("two-sided distance", self.two_sided_voxels)?;
        positive("max control share", self.max_control_share)?;
        if !(self.max_level_growth.is_finite() && self.max_level_growth > 1.0) {
            return Err(Error::input(format!(
                "max level growth {} must be a number above 1",
                self.max_level_growth
            )));
        }
        if !(0.0..=1.0).contains(&self.max_unmatched) {
            return Err(Error::input(format!(
                "max unmatched {} must be a fraction in [0, 1]",
                self.max_unmatched
            )));
        }
        if !(0.0..=1.0).contains(&self.max_unresolved) {
            return Err(Error::input(format!(
                "max unresolved {} must be a fraction in [0, 1]",
                self.max_unresolved
            )));
        }
        if !self.inflation.is_finite() {
            return Err(Error::input("inflation must be finite"));
        }
        if !(1..=8).contains(&self.quadrature_order) {
            return Err(Error::input(format!(
                "quadrature order {} must be between 1 and 8",
                self.quadrature_order
            )));
        }
        Ok(())
    }
}

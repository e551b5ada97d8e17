//! Parameters and report of the initial-model builders.

use crate::error::{Error, Result};
use crate::math::Real;

/// Which initial control mesh to build from a point cloud.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum InitKind {
    /// Detect: an open scan gets [`InitKind::Open`]; a closed one gets
    /// [`InitKind::Closed`] when its occupancy has genus 0 and
    /// [`InitKind::Occupancy`] otherwise (see [`super::closedness`]).
    #[default]
    Auto,
    /// Genus 0: a 26-vertex / 24-quad ellipsoid cage on the points' principal axes.
    Closed,
    /// One range view: an open quad grid over the points' principal plane.
    Open,
    /// Closed, any genus: the boundary of the points' voxel occupancy, smoothed.
    Occupancy,
}

impl InitKind {
    /// The lower-case name used on the command line (`auto`, `closed`, `open`, `occupancy`).
    pub fn name(self) -> &'static str {
        match self {
            InitKind::Auto => "auto",
            InitKind::Closed => "closed",
            InitKind::Open => "open",
            InitKind::Occupancy => "occupancy",
        }
    }
}

impl std::fmt::Display for InitKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for InitKind {
    type Err = Error;

    /// Parses `auto`, `closed`, `open` or `occupancy` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(InitKind::Auto),
            "closed" | "ellipsoid" => Ok(InitKind::Closed),
            "open" | "grid" => Ok(InitKind::Open),
            "occupancy" | "voxel" => Ok(InitKind::Occupancy),
            _ => Err(Error::input(format!(
                "unknown initial model '{s}': expected auto, closed, open or occupancy"
            ))),
        }
    }
}

/// Largest accepted [`InitParams::resolution`] (a 256³ occupancy grid is 16 M voxels).
pub const MAX_RESOLUTION: usize = 256;

/// Parameters of [`super::initial_mesh`]; every field's default is given.
#[derive(Clone, Debug, PartialEq)]
pub struct InitParams {
    /// Method. Default [`InitKind::Auto`].
    pub kind: InitKind,
    /// Cells along the longest axis: grid cells for [`InitKind::Open`] (along
    /// the longer side of the principal plane), voxels for
    /// [`InitKind::Occupancy`] (along the first principal axis). Holes of the
    /// object narrower than about 4 voxels close up. Default 12; 2 ..= 256.
    pub resolution: usize,
    /// Minimum value of the layered fraction (see [`super::closedness`]) for
    /// `Auto` to call a cloud closed. Default 0.3: single range views measure
    /// below 0.02, scans from three or more views above 0.6, from two 0.36.
    pub closed_threshold: Real,
    /// How much finer than `resolution` the occupancy voxel may become to
    /// keep a narrow gap between facing sheets open (legs, fingers; see
    /// [`super::gaps`]): the voxel is `gap / 1.5`, but at least `1 /
    /// max_refinement` of the resolution's voxel. Default 2; 1 disables;
    /// 1 ..= 8.
    pub max_refinement: Real,
    /// Taubin λ|μ smoothing steps applied to the occupancy cage. Default 10.
    pub smoothing_steps: usize,
    /// Minimum number of points for a grid cell to belong to the open
    /// footprint. Default 1.
    pub min_cell_points: usize,
}

impl Default for InitParams {
    fn default() -> Self {
        InitParams {
            kind: InitKind::Auto,
            resolution: 12,
            closed_threshold: 0.3,
            max_refinement: 2.0,
            smoothing_steps: 10,
            min_cell_points: 1,
        }
    }
}

impl InitParams {
    /// Checks the ranges documented on each field.
    pub fn validate(&self) -> Result<()> {
        if !(2..=MAX_RESOLUTION).contains(&self.resolution) {
            return Err(Error::out_of_range(format!(
                "initial-model resolution {} is out of range: expected 2 to {MAX_RESOLUTION} cells",
                self.resolution
            )));
        }
        if !(self.closed_threshold.is_finite() && (0.0..=1.0).contains(&self.closed_threshold)) {
            return Err(Error::out_of_range(format!(
                "closed threshold {} is out of range: expected a fraction in [0, 1]",
                self.closed_threshold
            )));
        }
        if !(1.0..=8.0).contains(&self.max_refinement) {
            return Err(Error::out_of_range(format!(
                "occupancy refinement {} is out of range: expected 1 to 8",
                self.max_refinement
            )));
        }
        if self.smoothing_steps > 1000 {
            return Err(Error::input(format!(
                "{} smoothing steps requested; at most 1000 allowed",
                self.smoothing_steps
            )));
        }
        if self.min_cell_points == 0 {
            return Err(Error::input(
                "min_cell_points must be at least 1 (empty cells are never part of the footprint)",
            ));
        }
        Ok(())
    }
}

/// What [`super::initial_mesh`] built and why.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct InitReport {
    /// The method used (never [`InitKind::Auto`]).
    pub chosen: InitKind,
    /// One or two sentences: the detection figures and the method's choices.
    pub reason: String,
    /// Genus of the control mesh from `V − E + F = 2c − 2g − b` (c components,
    /// b boundary loops); 0 for the ellipsoid and for an open grid.
    pub genus: Option<i64>,
    /// Control vertices.
    pub vertices: usize,
    /// Control faces (all quads).
    pub faces: usize,
    /// The outlier screening of the cloud, for the fit to reuse
    /// ([`crate::fit::fit_screened_cloud`]); `None` when the cloud was
    /// thinned (the screening then covers the thinned points alone).
    #[serde(skip)]
    pub screening: Option<super::outliers::Screening>,
    /// The occupancy cage with gap walls carved too, when its genus differs
    /// ([`super::occupancy::OccupancyCage::opened`]).
    #[serde(skip)]
    pub opened: Option<super::occupancy::Opened>,
}

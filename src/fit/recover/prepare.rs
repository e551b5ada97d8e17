//! The precompute step of the volume recovery: `G_σ * I`, the edge
//! potential, and the intensity separating inside from outside (Qin,
//! Mandal, Vemuri 1998, §4.2).

use std::time::Instant;

use super::{RecoverParams, padded_at_level};
use crate::error::{Error, Result};
use crate::forces::BoundaryModel;
use crate::math::{Point3, Real};
use crate::volume::{
    Volume, edge_potential, gaussian_smoothed, gaussian_smoothed_owned, otsu_threshold,
};

/// A volume ready for recovery: smoothed, padded, with its edge potential.
#[derive(Clone, Debug)]
pub struct PreparedVolume {
    /// `G_σ * I`, with one layer of outside samples on every side
    /// ([`padded_at_level`](super::padded_at_level)) so that an object cut
    /// by the box closes on its faces: its grid is the input's with
    /// [`PreparedVolume::PADDING`] more samples before and after each axis.
    pub smoothed: Volume,
    /// The edge potential (for [`BoundaryModel::Edge`]).
    pub potential: Option<Volume>,
    /// Intensity separating inside from outside: the iso-value, or Otsu's
    /// threshold of the smoothed volume.
    pub inside_level: Real,
    /// σ used, world units.
    pub sigma: Real,
    /// Seconds spent smoothing.
    pub smoothing_seconds: Real,
    /// Seconds spent on the potential.
    pub potential_seconds: Real,
}

impl PreparedVolume {
    /// Samples added before and after each axis of the input's grid.
    pub const PADDING: usize = 1;

    /// The input's grid: its samples per axis and its first sample's world
    /// point (the spacing is [`smoothed`](Self::smoothed)'s).
    pub fn input_grid(&self) -> ([usize; 3], Point3) {
        let pad = Self::PADDING;
        (
            self.smoothed.dims().map(|d| d - 2 * pad),
            self.smoothed.world([pad as Real; 3]),
        )
    }
}

/// The precompute step: smoothing, edge potential and inside level.
/// Errors for a constant volume or an iso-value outside its range. The
/// input and the smoothed copy are both alive at the end; see
/// [`prepare_volume_owned`] when the input is not needed afterwards.
pub fn prepare_volume(volume: &Volume, params: &RecoverParams) -> Result<PreparedVolume> {
    let sigma = checked_sigma(volume, params)?;
    let t = Instant::now();
    let smoothed = gaussian_smoothed(volume, sigma)?;
    finished(smoothed, sigma, t.elapsed().as_secs_f64(), params)
}

/// [`prepare_volume`] that gives up the input and smooths it in its own
/// samples ([`gaussian_smoothed_owned`]): the smoothed volume (and the
/// edge potential, for edges) are then the only volumes alive, one volume's
/// worth of memory less for the rest of the recovery. Same results.
pub fn prepare_volume_owned(volume: Volume, params: &RecoverParams) -> Result<PreparedVolume> {
    let sigma = checked_sigma(&volume, params)?;
    let t = Instant::now();
    let smoothed = gaussian_smoothed_owned(volume, sigma)?;
    finished(smoothed, sigma, t.elapsed().as_secs_f64(), params)
}

/// Checks the parameters against the volume (not constant; the iso-value
/// within its range) and returns σ in world units.
fn checked_sigma(volume: &Volume, params: &RecoverParams) -> Result<Real> {
    params.check()?;
    let (lo, hi) = volume.range();
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::input(format!(
            "the volume is constant ({lo}): there is no boundary to recover"
        )));
    }
    if let BoundaryModel::Iso { value } = params.boundary
        && !(value > lo as Real && value < hi as Real)
    {
        return Err(Error::input(format!(
            "iso-value {value} lies outside the volume's range [{lo}, {hi}]"
        )));
    }
    Ok(params.sigma.unwrap_or(
        match params.boundary {
            BoundaryModel::Iso { .. } => 0.25,
            BoundaryModel::Edge { .. } => 1.0,
        } * volume.voxel_size(),
    ))
}

/// The inside level of the smoothed volume, the padding and the potential.
fn finished(
    smoothed: Volume,
    sigma: Real,
    smoothing_seconds: Real,
    params: &RecoverParams,
) -> Result<PreparedVolume> {
    let t = Instant::now();
    let inside_level = match params.boundary {
        BoundaryModel::Iso { value } => value,
        BoundaryModel::Edge { .. } => otsu_threshold(&smoothed)? as Real,
    };
    let smoothed = padded_at_level(&smoothed, inside_level, params.bright_inside)?;
    let potential = match params.boundary {
        BoundaryModel::Iso { .. } => None,
        BoundaryModel::Edge { .. } => Some(edge_potential(&smoothed)?),
    };
    Ok(PreparedVolume {
        smoothed,
        potential,
        inside_level,
        sigma,
        smoothing_seconds,
        potential_seconds: t.elapsed().as_secs_f64(),
    })
}

//! The multilevel fitting driver (Qin, Mandal, Vemuri 1998, §6).
//!
//! At each level the control points follow the first-order (massless)
//! dynamics `D ṗ + K p = f_p` with implicit Euler steps, the data springs
//! treated implicitly ([`super::system::LevelSystem::step`]),
//! refreshing every spring's closest point before each step. Each step
//! minimises the spring + stiffness energy plus a proximal term, and the
//! closest-point refresh can only lower the spring energy, so the energy
//! `½ Σ k |x − d|² + ½ pᵀ K p` decreases monotonically (with fixed robust
//! weights). When it settles (relative change below the tolerance) the error
//! is measured; above the tolerance the control mesh is subdivided and the
//! fit goes on. Uniform refinement splits every face (the new control points
//! `S p` describe the same surface). Adaptive refinement (the default)
//! splits only the faces whose data residual is above the noise
//! ([`super::refine_marks`], [`crate::subdivision::refine_marked`]) and puts
//! the new control mesh's limit points on the parent's surface by
//! progressive interpolation; should such a level fit worse than its parent
//! (transitions on a very coarse mesh can bend the surface), the parent is
//! refined uniformly instead and the report says so.
//!
//! With a mass (`FitParams::mass` > 0) the steps integrate the paper's
//! second-order dynamics `M p̈ + D ṗ + K p = f_p` (eq. 16) by backward
//! differences, unconditionally stable like the first-order step. The model
//! then carries momentum, so the potential energy may rise for a step while
//! it overshoots; the stop rules ([`super::levels`]) are the same.
//!
//! The loop itself is [`super::levels::run_levels`], shared with the volume
//! recovery; the fit is its force source `CloudFit`
//! (`super::cloud_levels`), and the untangling after the last level is
//! `super::untangle`.

use crate::error::Result;
use crate::math::Real;
use crate::mesh::{PointCloud, PolyMesh};
use crate::subdivision::RefineOptions;

use super::cloud_levels::CloudFit;
use super::creases::Crease;
use super::init::outliers::Screening;
use super::levels::run_levels;
use super::quality::assess;
use super::untangle::untangle_after_fit;
use super::{FitParams, FitReport};

/// A fitted model and what it took.
#[derive(Clone, Debug)]
pub struct FitResult {
    /// The control mesh of the finest level reached.
    pub control: PolyMesh,
    /// Its sharp edges `(i, j, s)` (`i < j`, `s` = [`SHARPNESS_INFINITE`]):
    /// the creases found in the data ([`FitParams::crease_angle`]); the
    /// limit surface is `control`'s with these tags
    /// ([`crease_options`]).
    pub creases: Vec<Crease>,
    /// Per-level report.
    pub report: FitReport,
}

/// The refinement options of a fitted control mesh with these `creases`.
pub fn crease_options(creases: &[Crease]) -> RefineOptions {
    RefineOptions {
        creases: creases.to_vec(),
        ..Default::default()
    }
}

/// Fits the limit surface of a control mesh, starting from `init`, to the
/// points of `cloud`. `progress` is called after every implicit step with
/// `(level, step, energy)`.
pub fn fit_point_cloud(
    cloud: &PointCloud,
    init: &PolyMesh,
    params: &FitParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<FitResult> {
    fit_screened_cloud(cloud, None, init, params, progress)
}

/// [`fit_point_cloud`] with the cloud's outlier screening already done
/// (`screening`, as [`crate::fit::init::initial_mesh`] reports it; `None`:
/// screened here). Errors when it is not of the cloud's length.
pub fn fit_screened_cloud(
    cloud: &PointCloud,
    screening: Option<&Screening>,
    init: &PolyMesh,
    params: &FitParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<FitResult> {
    params.check()?;
    let mut fit = CloudFit::new(cloud, screening, params, progress)?;
    let mut mesh = init.clone();
    let mut creases = Vec::new();
    let (converged, stop_reason) = run_levels(
        &mut fit,
        &mut mesh,
        &mut creases,
        params.max_level,
        params.min_level_gain,
    )?;
    let (crossings, final_untangling) = untangle_after_fit(
        &mut mesh,
        &creases,
        params.final_untangle_rounds,
        &fit.quadtrees,
    )?;
    let kept_dist: Vec<Real> = fit.data_index.iter().map(|&i| fit.final_dist[i]).collect();
    let quality = assess(
        &mesh,
        crossings,
        &fit.data,
        &fit.data_tree,
        &kept_dist,
        fit.diameter,
    )?;
    let seconds = fit.started().elapsed().as_secs_f64();
    Ok(FitResult {
        control: mesh,
        creases,
        report: FitReport {
            quality,
            noise: fit.data_noise,
            points: cloud.positions.len(),
            outliers: fit.outliers(),
            diameter: fit.diameter,
            levels: fit.levels,
            converged,
            stop_reason,
            final_untangling,
            seconds,
        },
    })
}

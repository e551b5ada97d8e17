//! [`fit_from_start`]: the whole `subdyn fit` job on a point cloud (the
//! initial model, then the fit), shared by the CLI and the Python package so
//! both give the same control mesh and the same report.

use serde_json::{Map, Value, json};

use super::driver::{FitResult, fit_screened_cloud};
use super::init::outliers::Screening;
use super::init::{InitParams, initial_mesh, surface_topology};
use super::params::{FitParams, ToleranceStat};
use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::{PointCloud, PolyMesh};
use crate::subdivision::{RefineOptions, Refiner};

/// Fewest points [`fit_from_start`] accepts.
pub const MIN_FIT_POINTS: usize = 10;

/// Where a fit starts.
#[derive(Clone, Debug)]
pub enum FitStart {
    /// An initial model built from the points ([`initial_mesh`]).
    Method(InitParams),
    /// A given control mesh (checked to be subdividable).
    Mesh(PolyMesh),
}

/// What [`fit_from_start`] returns.
#[derive(Clone, Debug)]
pub struct FitRun {
    /// The initial control mesh.
    pub init: PolyMesh,
    /// The fit: the final control mesh and the per-level report.
    pub result: FitResult,
    /// The `init` object of `subdyn fit --report`: `method`, `reason`,
    /// `genus`, `vertices`, `faces` for a built model; `method: "mesh"`,
    /// `vertices`, `faces` for a given one.
    pub init_report: Value,
}

impl FitRun {
    /// The fields of `subdyn fit --report` that describe the work (`init`,
    /// `tolerance_pct`, `tolerance_stat`, `fit`); the caller adds where the
    /// input and outputs are and the total time.
    pub fn report(&self, params: &FitParams) -> Result<Map<String, Value>> {
        let fit = serde_json::to_value(&self.result.report)
            .map_err(|e| Error::Input(format!("the fit report cannot be serialised: {e}")))?;
        let mut map = Map::new();
        map.insert("init".into(), self.init_report.clone());
        map.insert("tolerance_pct".into(), json!(params.tolerance_pct));
        map.insert(
            "tolerance_stat".into(),
            json!(stat_name(params.tolerance_stat)),
        );
        map.insert("crease_angle".into(), json!(params.crease_angle));
        map.insert("creases".into(), json!(self.result.creases.len()));
        map.insert("fit".into(), fit);
        Ok(map)
    }
}

/// The lower-case name of a tolerance statistic (`max`, `p95`, `rms`, `mean`).
pub fn stat_name(stat: ToleranceStat) -> &'static str {
    match stat {
        ToleranceStat::Max => "max",
        ToleranceStat::P95 => "p95",
        ToleranceStat::Rms => "rms",
        ToleranceStat::Mean => "mean",
    }
}

/// The opened occupancy cage ([`crate::fit::init::occupancy::OccupancyCage::opened`])
/// replaces the other when the area of its level-0 surface far from the
/// points is below this fraction of the other's: a web across a slot or
/// hole is far from every point, a false handle leaves as much far surface
/// or more. Level-0 far-surface fractions (%), opened / not, on the corpus
/// (`benches/compare`): plate-n1 0.01 / 2.25, plate-n3 0.01 / 3.43,
/// bracket-n1 1.92 / 4.03, bracket-out 2.49 / 3.01; on other scans: a
/// bracket at seed 3 1.21 / 2.20, a Spot scan whose dents open a false
/// handle 0.88 / 0.72.
const OPENED_FAR_SURFACE: Real = 0.9;

/// The fraction of the surface far from the points
/// ([`crate::fit::quality::FitQuality::far_surface_fraction`]) after level
/// 0 is fitted from `cage` (no crease trial, no final untangling).
fn far_surface_at_level_0(
    cloud: &PointCloud,
    screening: Option<&Screening>,
    cage: &PolyMesh,
    params: &FitParams,
) -> Result<Real> {
    let trial = FitParams {
        max_level: 0,
        crease_angle: 0.0,
        final_untangle_rounds: 0,
        ..params.clone()
    };
    let fit = fit_screened_cloud(cloud, screening, cage, &trial, &mut |_, _, _| {})?;
    Ok(fit.report.quality.far_surface_fraction)
}

/// Fits `cloud` from `start` with `params`: at least [`MIN_FIT_POINTS`]
/// points, the initial model (reusing its outlier screening for the fit),
/// then [`fit_screened_cloud`]. `progress` is called after every implicit
/// step with `(level, step, energy)`.
pub fn fit_from_start(
    cloud: &PointCloud,
    start: &FitStart,
    params: &FitParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<FitRun> {
    params.check()?;
    if cloud.len() < MIN_FIT_POINTS {
        return Err(Error::Input(format!(
            "{} points; a fit needs at least {MIN_FIT_POINTS} points spread over the surface",
            cloud.len()
        )));
    }
    let (init, init_report, screening) = match start {
        FitStart::Method(init_params) => {
            let (mut mesh, mut report) = initial_mesh(cloud, init_params)?;
            if let Some(opened) = report.opened.take() {
                let (far, far_opened) = (
                    far_surface_at_level_0(cloud, report.screening.as_ref(), &mesh, params)?,
                    far_surface_at_level_0(cloud, report.screening.as_ref(), &opened, params)?,
                );
                let keep = far_opened < OPENED_FAR_SURFACE * far;
                let genus = surface_topology(&opened)?.genus;
                report.reason = format!(
                    "{}; with gap walls carved too, genus {genus}: surface far from the points \
                     at level 0 {:.2} % against {:.2} %, {}",
                    report.reason,
                    100.0 * far_opened,
                    100.0 * far,
                    if keep { "taken" } else { "not taken" }
                );
                if keep {
                    mesh = opened;
                    report.genus = Some(genus);
                }
            }
            let value = json!({
                "method": report.chosen.name(),
                "reason": report.reason,
                "genus": report.genus,
                "vertices": mesh.num_vertices(),
                "faces": mesh.num_faces(),
            });
            (mesh, value, report.screening)
        }
        FitStart::Mesh(mesh) => {
            Refiner::new(mesh, &RefineOptions::default())?;
            let value = json!({
                "method": "mesh",
                "vertices": mesh.num_vertices(),
                "faces": mesh.num_faces(),
            });
            (mesh.clone(), value, None)
        }
    };
    let result = fit_screened_cloud(cloud, screening.as_ref(), &init, params, progress)?;
    Ok(FitRun {
        init,
        result,
        init_report,
    })
}

//! [`fit_from_start`]: the whole `subdyn fit` job on a point cloud (the
//! initial model, then the fit), shared by the CLI and the Python package so
//! both give the same control mesh and the same report.

use serde_json::{Map, Value, json};

use super::driver::{FitResult, fit_screened_cloud};
use super::init::{InitParams, initial_mesh};
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
            let (mesh, report) = initial_mesh(cloud, init_params)?;
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

//! `fit`: the job of `subdyn fit` on numpy points, through the same library
//! call ([`subdyn::fit::fit_from_start`]) so that the control mesh and the
//! report are the CLI's.

use std::time::Instant;

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::json;

use subdyn::fit::init::{InitKind, InitParams};
use subdyn::fit::{FitParams, FitStart, Refinement, ToleranceStat, crease_options, fit_from_start};
use subdyn::mesh::{PointCloud, PolyMesh};

use crate::arrays::{
    crease_array, mesh, mesh_arrays, points, value_error, vector_array, vectors, without_gil,
};
use crate::options::Options;
use subdyn::limit::limit_surface_mesh;

/// The options of `fit` (the CLI's flags that describe the work).
const FIT_OPTIONS: &[&str] = &[
    "init",
    "tol",
    "tol_stat",
    "max_level",
    "refine",
    "refine_significance",
    "refine_off_data",
    "tension",
    "bending",
    "fairness",
    "untangle_rounds",
    "final_untangle_rounds",
    "crease_angle",
    "init_resolution",
    "mass",
    "tess",
    "quads",
    "threads",
];

/// Largest tessellation rate of the fitted limit surface (as `subdyn fit --tess`).
const MAX_FIT_TESS: usize = 64;

/// Fits `points` (with optional `normals`); `init_mesh` is a given initial
/// control mesh (vertices, face vertices, face offsets), else the option
/// `init` names a method. Returns a dict of arrays and the report as JSON.
#[pyfunction]
#[pyo3(signature = (points, normals=None, init_mesh=None, options=None))]
pub fn fit<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    normals: Option<PyReadonlyArray2<'py, f64>>,
    init_mesh: Option<(
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray1<'py, i64>,
        PyReadonlyArray1<'py, i64>,
    )>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let started = Instant::now();
    let o = Options::new(options, "subdyn.fit", FIT_OPTIONS)?;
    let params = fit_params(&o)?;
    let tess = o.usize("tess", 4)?;
    if tess == 0 || tess > MAX_FIT_TESS {
        return Err(value_error(format!(
            "tess {tess} is out of range: expected 1 to {MAX_FIT_TESS}"
        )));
    }
    let quads = o.flag("quads")?;
    let threads = o.opt_usize("threads")?;
    let positions = self::points(&points, "points")?;
    let normals = match &normals {
        Some(n) => Some(vectors(n, "normals")?),
        None => None,
    };
    let n = positions.len();
    let cloud = PointCloud::new(positions, normals).map_err(crate::arrays::py_err)?;
    let start = match &init_mesh {
        Some((v, fv, fo)) => FitStart::Mesh(mesh(v, fv, fo)?),
        None => {
            let method = o.string("init", "auto")?;
            let kind = method
                .parse::<InitKind>()
                .map_err(|e| value_error(e.to_string()))?;
            FitStart::Method(InitParams {
                kind,
                resolution: o.usize("init_resolution", InitParams::default().resolution)?,
                ..Default::default()
            })
        }
    };
    let (run, limit, report) = without_gil(py, threads, || {
        let run = fit_from_start(&cloud, &start, &params, &mut |_, _, _| {})?;
        let limit = limit_surface_mesh(
            &run.result.control,
            &crease_options(&run.result.creases),
            tess,
            quads,
        )?;
        let mut report = json!({
            "command": "fit",
            "input": format!("an array of {n} points"),
            "output": null,
            "limit_out": null,
            "crease_file": null,
        });
        if let Some(map) = report.as_object_mut() {
            map.extend(run.report(&params)?);
            map.insert("total_s".into(), json!(started.elapsed().as_secs_f64()));
        }
        Ok((run, limit, report))
    })?;
    result_dict(
        py,
        &run.init,
        &run.result.control,
        &run.result.creases,
        &limit,
        &report,
    )
}

/// `FitParams` from the options, with the CLI's defaults.
fn fit_params(o: &Options<'_, '_>) -> PyResult<FitParams> {
    let d = FitParams::default();
    let tolerance_stat = match o
        .choice("tol_stat", "p95", &["max", "p95", "rms", "mean"])?
        .as_str()
    {
        "max" => ToleranceStat::Max,
        "rms" => ToleranceStat::Rms,
        "mean" => ToleranceStat::Mean,
        _ => ToleranceStat::P95,
    };
    let refinement = match o
        .choice("refine", "adaptive", &["adaptive", "uniform"])?
        .as_str()
    {
        "uniform" => Refinement::Uniform,
        _ => Refinement::Adaptive,
    };
    let params = FitParams {
        tolerance_pct: o.f64("tol", d.tolerance_pct)?,
        tolerance_stat,
        max_level: o.usize("max_level", d.max_level)?,
        refinement,
        refine_significance: o.f64("refine_significance", d.refine_significance)?,
        refine_off_data: o.f64("refine_off_data", d.refine_off_data)?,
        tension: o.f64("tension", d.tension)?,
        bending: o.f64("bending", d.bending)?,
        fairness: o.f64("fairness", d.fairness)?,
        untangle_rounds: o.usize("untangle_rounds", d.untangle_rounds)?,
        final_untangle_rounds: o.usize("final_untangle_rounds", d.final_untangle_rounds)?,
        crease_angle: o.f64("crease_angle", d.crease_angle)?,
        mass: o.f64("mass", d.mass)?,
        ..d
    };
    params.check().map_err(crate::arrays::py_err)?;
    Ok(params)
}

/// What `fit` and `recover` return: the initial and the final control mesh,
/// the limit tessellation with its normals, and the report as JSON text.
pub fn result_dict<'py>(
    py: Python<'py>,
    init: &PolyMesh,
    control: &PolyMesh,
    creases: &[(u32, u32, f64)],
    limit: &(PolyMesh, Vec<subdyn::math::Vector3>),
    report: &serde_json::Value,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("init", mesh_arrays(py, init))?;
    d.set_item("control", mesh_arrays(py, control))?;
    d.set_item("creases", crease_array(py, creases))?;
    d.set_item("limit", mesh_arrays(py, &limit.0))?;
    d.set_item("limit_normals", vector_array(py, &limit.1))?;
    d.set_item("report", report.to_string())?;
    Ok(d)
}

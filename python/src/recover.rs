//! `recover`: the job of `subdyn recover` on a numpy volume, through the
//! same library calls (prepare, initial model, evolution).

use std::time::Instant;

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::json;

use subdyn::fit::Refinement;
use subdyn::fit::recover::{
    BONE_HU, InitialModel, RecoverParams, RecoverStart, SKIN_HU, initial_model, opened_at_box,
    poor_result, prepare_volume_owned, recover_shape,
};
use subdyn::forces::BoundaryModel;
use subdyn::math::Point3;
use subdyn::volume::Volume;

use crate::arrays::{mesh, points, value_error, without_gil};
use crate::fit::result_dict;
use crate::options::Options;
use subdyn::limit::limit_surface_mesh;

/// The options of `recover` (the CLI's flags that describe the work).
const RECOVER_OPTIONS: &[&str] = &[
    "seed",
    "auto",
    "iso",
    "preset",
    "edge_strength",
    "dark",
    "sigma",
    "tol",
    "max_level",
    "resolution",
    "seed_radius",
    "points_weight",
    "two_sided_weight",
    "two_sided_distance",
    "max_unmatched",
    "refine",
    "max_level_growth",
    "max_control_share",
    "bending",
    "tess",
    "quads",
    "threads",
    "accept_poor",
    "open_at_box",
];

/// Recovers a closed shape from `data` (x fastest, `dims` samples) on the
/// grid `origin + (i sx, j sy, k sz)`; `points` are user-placed boundary
/// points, `init_mesh` a given initial control mesh.
#[pyfunction]
#[pyo3(signature = (data, dims, spacing, origin, points=None, init_mesh=None, options=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn recover<'py>(
    py: Python<'py>,
    data: PyReadonlyArray1<'py, f32>,
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    points: Option<PyReadonlyArray2<'py, f64>>,
    init_mesh: Option<(
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray1<'py, i64>,
        PyReadonlyArray1<'py, i64>,
    )>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let started = Instant::now();
    let o = Options::new(options, "subdyn.recover", RECOVER_OPTIONS)?;
    let d = RecoverParams::default();
    let dark = o.flag("dark")?;
    let params = RecoverParams {
        boundary: match iso_value(&o)? {
            Some(value) => BoundaryModel::Iso { value },
            None => BoundaryModel::Edge {
                min_strength: o.f64("edge_strength", 0.1)?,
            },
        },
        sigma: o.opt_f64("sigma")?,
        bright_inside: !dark,
        tolerance_voxels: o.f64("tol", 0.5)?,
        max_level: o.usize("max_level", 3)?,
        bending: o.f64("bending", d.bending)?,
        points_weight: o.f64("points_weight", d.points_weight)?,
        two_sided_weight: o.f64("two_sided_weight", d.two_sided_weight)?,
        two_sided_voxels: o.f64("two_sided_distance", d.two_sided_voxels)?,
        max_unmatched: o.f64("max_unmatched", d.max_unmatched)?,
        refinement: match o
            .choice("refine", "adaptive", &["adaptive", "uniform"])?
            .as_str()
        {
            "uniform" => Refinement::Uniform,
            _ => Refinement::Adaptive,
        },
        max_level_growth: o.f64("max_level_growth", d.max_level_growth)?,
        max_control_share: o.f64("max_control_share", d.max_control_share)?,
        ..d
    };
    params.check().map_err(crate::arrays::py_err)?;
    let tess = o.usize("tess", 4)?;
    if tess == 0 || tess > 64 {
        return Err(value_error(format!(
            "tess {tess} is out of range: expected 1 to 64"
        )));
    }
    let quads = o.flag("quads")?;
    let accept_poor = o.flag("accept_poor")?;
    let open_at_box = o.flag("open_at_box")?;
    let threads = o.opt_usize("threads")?;
    let seed = o.triple("seed")?.map(|s| Point3::new(s[0], s[1], s[2]));
    let start = match (&init_mesh, seed) {
        (Some((v, fv, fo)), _) => RecoverStart::Mesh(mesh(v, fv, fo)?),
        (None, Some(point)) if !o.flag("auto")? => RecoverStart::Seed {
            point,
            radius_voxels: o.f64("seed_radius", 3.0)?,
        },
        _ => RecoverStart::Auto {
            seed,
            resolution: o.usize("resolution", 24)?,
        },
    };
    let points = match &points {
        Some(p) => self::points(p, "points")?,
        None => Vec::new(),
    };
    let data = data.as_array().to_vec();
    let (init, control, limit, report) = without_gil(py, threads, || {
        let volume = Volume::new(dims, data, spacing, Point3::from(origin))?;
        let prepared = prepare_volume_owned(volume, &params)?;
        let t = Instant::now();
        let InitialModel {
            mesh: init,
            boundary,
            report: init_json,
        } = initial_model(&prepared, &start, !dark)?;
        let init_s = t.elapsed().as_secs_f64();
        let result = recover_shape(
            &prepared,
            &init,
            &points,
            &boundary,
            &params,
            &mut |_, _, _| {},
        )?;
        let problems = poor_result(&result.report, &params);
        if !problems.is_empty() && !accept_poor {
            return Err(subdyn::Error::NotConverged(format!(
                "poor result: {}; accept_poor=True returns it anyway",
                problems.join("; ")
            )));
        }
        let control = if open_at_box {
            opened_at_box(&result.control, &prepared.smoothed)?
        } else {
            result.control
        };
        let limit = limit_surface_mesh(&control, &Default::default(), tess, quads)?;
        let (grid_dims, grid_origin) = prepared.input_grid();
        let report = json!({
            "command": "recover",
            "input": format!("an array of {}×{}×{} voxels", dims[0], dims[1], dims[2]),
            "padding": subdyn::fit::recover::PreparedVolume::PADDING,
            "dims": grid_dims,
            "spacing": prepared.smoothed.spacing(),
            "origin": [grid_origin.x, grid_origin.y, grid_origin.z],
            "output": null,
            "limit_out": null,
            "init": init_json,
            "stages_s": {
                "smoothing": prepared.smoothing_seconds,
                "potential": prepared.potential_seconds,
                "init": init_s,
                "evolution": result.report.levels.iter().map(|l| l.seconds).sum::<f64>(),
            },
            "recover": serde_json::to_value(&result.report)
                .map_err(|e| subdyn::Error::input(format!("the report cannot be serialised: {e}")))?,
            "poor_result": problems,
            "total_s": started.elapsed().as_secs_f64(),
        });
        Ok((init, control, limit, report))
    })?;
    result_dict(py, &init, &control, &[], &limit, &report)
}

/// The iso-value of `iso=` or of `preset=` ("skin" or "bone", Hounsfield
/// units), not both; `None` for edges.
fn iso_value(o: &Options) -> PyResult<Option<f64>> {
    let iso = o.opt_f64("iso")?;
    let preset = match o
        .choice("preset", "none", &["none", "skin", "bone"])?
        .as_str()
    {
        "skin" => Some(SKIN_HU),
        "bone" => Some(BONE_HU),
        _ => None,
    };
    match (iso, preset) {
        (Some(_), Some(_)) => Err(value_error("give iso or preset, not both")),
        (iso, preset) => Ok(iso.or(preset)),
    }
}

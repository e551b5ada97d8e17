//! JSON files of curve fine tuning: the input curve, the control values of
//! `α`, and the fine-tuned B-spline.
//!
//! **Curve** (`CURVE.json`):
//! `{"scheme": "quadratic" | "cubic", "closed": true, "points": [[x, y], [x, y, z], …]}`
//! — points are 2-D (`z = 0`) or 3-D, all finite; `closed` defaults to `false`.
//!
//! **Values** (`V.json`): `{"degree": 1 | 2 | 3, "values": [a_0, a_1, …]}` —
//! one positive value per edge or vertex of the control polygon, as
//! `curve_alpha` lays down (edge `e` joins points `e` and `e + 1`).
//!
//! **Output**: `{"degree", "closed", "knots", "control_points", "domain",
//! "samples"}` — an ordinary B-spline (`N` control points, `N + degree + 1`
//! knots, defined on `domain = [knots[degree], knots[N]]`); a closed curve
//! starts with wrapped copies of its last few control points (`degree + 1 −
//! m` of them, `m` the knot multiplicity), so the same formula traces it. `samples` are 20 points per unit of parameter, for plotting.

use std::path::Path;

use serde::Deserialize;
use serde_json::json;

use crate::error::{Error, Result};
use crate::io::atomic_write;
use crate::math::{Point3, Real};
use crate::subdivision::{CurveScheme, CurveTopology};

use super::curve_alpha::{ScalarFunction, alpha_from_values};
use super::curve_bspline::BSplineCurve;

/// Largest accepted input file, in bytes.
const MAX_BYTES: u64 = 256 << 20;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveFile {
    scheme: String,
    #[serde(default)]
    closed: bool,
    points: Vec<Vec<Real>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ValuesFile {
    degree: usize,
    values: Vec<Real>,
}

/// Reads a JSON file into `T`, with the line of a syntax or shape error.
fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T> {
    let bytes = crate::io::read_input(path)?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(Error::parse(
            path,
            0,
            format!("file is larger than {MAX_BYTES} bytes"),
        ));
    }
    let text = String::from_utf8(bytes)
        .map_err(|_| Error::parse(path, 0, "the file is not UTF-8 text"))?;
    serde_json::from_str(&text).map_err(|e| Error::parse(path, e.line(), e.to_string()))
}

/// Reads a curve file: its topology and control points.
pub fn read_curve(path: &Path) -> Result<(CurveTopology, Vec<Point3>)> {
    let file: CurveFile = read_json(path)?;
    let scheme = match file.scheme.as_str() {
        "quadratic" => CurveScheme::Quadratic,
        "cubic" => CurveScheme::Cubic,
        other => {
            return Err(Error::parse(
                path,
                0,
                format!("scheme must be \"quadratic\" or \"cubic\", got {other:?}"),
            ));
        }
    };
    let mut points = Vec::with_capacity(file.points.len());
    for (i, p) in file.points.iter().enumerate() {
        if !(p.len() == 2 || p.len() == 3) || p.iter().any(|c| !c.is_finite()) {
            return Err(Error::parse(
                path,
                0,
                format!("point {i} must be 2 or 3 finite numbers, got {p:?}"),
            ));
        }
        points.push(Point3::new(p[0], p[1], p.get(2).copied().unwrap_or(0.0)));
    }
    let topo = CurveTopology::new(scheme, points.len(), file.closed)
        .map_err(|e| Error::parse(path, 0, e.to_string()))?;
    Ok((topo, points))
}

/// Reads a values file and builds `α` for `topo`.
pub fn read_alpha(path: &Path, topo: &CurveTopology) -> Result<ScalarFunction> {
    let file: ValuesFile = read_json(path)?;
    alpha_from_values(topo, file.degree, &file.values)
        .map_err(|e| Error::parse(path, 0, e.to_string()))
}

/// The output JSON of a fine-tuned curve.
pub fn curve_json(curve: &BSplineCurve, closed: bool) -> serde_json::Value {
    let (t0, t1) = curve.domain();
    let count = ((t1 - t0) * 20.0).ceil().max(1.0) as usize;
    let xyz = |p: &Point3| json!([p.x, p.y, p.z]);
    json!({
        "degree": curve.degree,
        "closed": closed,
        "knots": curve.knots,
        "control_points": curve.control_points.iter().map(xyz).collect::<Vec<_>>(),
        "domain": [t0, t1],
        "samples": curve.samples(count).iter().map(xyz).collect::<Vec<_>>(),
    })
}

/// Writes `value` as pretty JSON to `path`, all or nothing.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    atomic_write(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

//! Inflation: a pressure along the surface normal.
//!
//! `f_p = ∫∫ P Jᵀ n dA = ∫∫ P Jᵀ (x_u × x_v) du dv` (Qin et al. 1998, §5: the
//! balloon force used to grow a model inside a volume). With the unnormalised
//! normal `x_u × x_v` the area element is already included.

use crate::dynamics::SampleRows;
use crate::error::{Error, Result};
use crate::math::{Point3, Real};

/// Generalised force over the control points of pressure `pressure`
/// (positive pushes along the outward normal `x_u × x_v`) at control
/// positions `p`, integrated over the samples `rows`.
pub fn inflation_force(rows: &SampleRows, p: &[Point3], pressure: Real) -> Result<Vec<Point3>> {
    if !pressure.is_finite() {
        return Err(Error::Input(format!("pressure {pressure} is not finite")));
    }
    let du = rows.ju.apply(p)?;
    let dv = rows.jv.apply(p)?;
    let f: Vec<Point3> = rows
        .weights
        .iter()
        .zip(du.iter().zip(&dv))
        .map(|(w, (a, b))| Point3::from(pressure * w * a.coords.cross(&b.coords)))
        .collect();
    rows.j.apply_transpose(&f)
}

//! Inflation: a pressure along the surface normal.
//!
//! `f_p = ∫∫ P Jᵀ n dA = ∫∫ P Jᵀ (x_u × x_v) du dv` (Qin et al. 1998, §5: the
//! balloon force used to grow a model inside a volume). With the unnormalised
//! normal `x_u × x_v` the area element is already included.

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;

/// Generalised force over the control points of pressure `pressure`
/// (positive pushes along the outward normal `x_u × x_v`), integrated over
/// samples with position rows `j`, tangents `du`, `dv` and quadrature
/// weights `weights` (in the parameter's `du dv`).
pub fn inflation_force(
    j: &StencilTable,
    du: &[Point3],
    dv: &[Point3],
    weights: &[Real],
    pressure: Real,
) -> Result<Vec<Point3>> {
    if !pressure.is_finite() {
        return Err(Error::non_finite(format!(
            "pressure {pressure} is not finite"
        )));
    }
    if du.len() != weights.len() || dv.len() != weights.len() || j.num_rows() != weights.len() {
        return Err(Error::input(format!(
            "inflation: {} rows, {} and {} tangents, {} weights",
            j.num_rows(),
            du.len(),
            dv.len(),
            weights.len()
        )));
    }
    let f: Vec<Point3> = weights
        .iter()
        .zip(du.iter().zip(dv))
        .map(|(w, (a, b))| Point3::from(pressure * w * a.coords.cross(&b.coords)))
        .collect();
    j.apply_transpose(&f)
}

//! Inflation: a pressure along the surface normal.
//!
//! `f_p = ∫∫ P Jᵀ n dA = ∫∫ P Jᵀ (x_u × x_v) du dv` (Qin et al. 1998, §5: the
//! balloon force used to grow a model inside a volume). With the unnormalised
//! normal `x_u × x_v` the area element is already included.

use crate::dynamics::Quadrature;
use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;

/// Generalised force of pressure `pressure` (positive pushes along the
/// outward normal `x_u × x_v`) at the level-`L` positions `level_positions`,
/// over the control points (`s` maps them: `P_L = S P_0`).
pub fn inflation_force(
    q: &Quadrature,
    s: &StencilTable,
    level_positions: &[Point3],
    pressure: Real,
) -> Result<Vec<Point3>> {
    if !pressure.is_finite() {
        return Err(Error::Input(format!("pressure {pressure} is not finite")));
    }
    let du = q.rows.du.apply(level_positions)?;
    let dv = q.rows.dv.apply(level_positions)?;
    let f: Vec<Point3> = q
        .weights
        .iter()
        .zip(du.iter().zip(&dv))
        .map(|(w, (a, b))| Point3::from(pressure * w * a.coords.cross(&b.coords)))
        .collect();
    // Jᵀ f over level L, then Sᵀ to the control points.
    s.apply_transpose(&q.rows.p.apply_transpose(&f)?)
}

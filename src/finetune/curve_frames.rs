//! The reduced variables of closed-curve fine tuning: the legs, with one
//! point and one rotation fixed (fine-tuning paper, §4.2: "the position of at
//! least one point and rotation about at least one point of the curve should
//! be fixed to avoid rigid motion").
//!
//! Starting at the fixed point `p_0 = C_f`, the polygon is walked leg by leg:
//! `p_{t+1} = p_t + d_t` for `t = 0 … N − 2`, and the last leg closes it
//! (`p_{N−1} → p_0`), so the polygon is closed for every choice of variables.
//! - leg `d_0` keeps the initial direction `u` (1 variable: fixes the rotation
//!   in the plane);
//! - 3-D only: the first later leg with a part `w ⟂ u` stays in the plane
//!   `span(u, w)` (2 variables: fixes the rotation about `u`);
//! - every other leg is free (2 variables in the plane of a planar curve, 3
//!   otherwise).
//!
//! **Why legs, not points.** Energy (13) measures legs and the angles between
//! them; in leg coordinates each term depends on one or two variables plus
//! the closing leg. On the 8-leg test curves (6 scheme / degree pairs) this
//! reached the rounding-level stall in 1 075 – 6 323 NCG iterations against
//! 1 245 – 9 814 in point coordinates: better, but convergence is still slow
//! (7 000 – 23 000 iterations to `|∇E| ≤ 1e-6` on a 100-leg ring).
//!
//! **Jacobi scaling.** Every axis of leg `t` is multiplied by `s_t = 1/√h_t`,
//! `h_t = 2 k_l + 4 k_a / l_t²` (Gauss-Newton diagonal across the leg: the
//! length term, and the two joint angles at its ends, `|∂θ/∂d_t| = 1/l_t`),
//! `l_t` the initial leg length. The minimiser is unchanged. (Scaling the
//! along-leg axis by `1/√(2 k_l)` instead, the exact diagonal there, made the
//! first steps so long that the line search failed on 100-leg curves.)

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::curve_solver::LegFrame;

/// The leg frames (in walking order from the fixed point) and the starting
/// variables that reproduce `points`.
pub fn leg_frames(
    points: &[Point3],
    fixed: usize,
    planar: bool,
    k_length: Real,
    k_angle: Real,
) -> Result<(Vec<LegFrame>, Vec<Real>)> {
    let n = points.len();
    if fixed >= n {
        return Err(Error::out_of_range(format!(
            "fixed point {fixed} is out of range: the fine-tuned polygon has {n} control points"
        )));
    }
    let legs: Vec<Vector3> = (0..n - 1)
        .map(|t| points[(fixed + t + 1) % n] - points[(fixed + t) % n])
        .collect();
    let u = legs[0].try_normalize(1e-12).ok_or_else(|| {
        Error::input(format!("the leg after fixed point {fixed} has zero length"))
    })?;
    let plane_leg = if planar {
        None
    } else {
        let found = (1..n - 1).find_map(|t| {
            let d = legs[t];
            (d - d.dot(&u) * u).try_normalize(1e-9).map(|w| (t, w))
        });
        Some(found.ok_or_else(|| Error::input("the fine-tuned polygon is a straight line"))?)
    };
    let mut frames = Vec::with_capacity(n - 1);
    let mut start = Vec::with_capacity(3 * n);
    for (t, d) in legs.iter().enumerate() {
        let l = d.norm().max(1e-12);
        let s = 1.0 / (2.0 * k_length + 4.0 * k_angle / (l * l)).sqrt();
        let axes: Vec<Vector3> = if t == 0 {
            vec![u]
        } else if let Some((_, w)) = plane_leg.filter(|(g, _)| *g == t) {
            vec![u, w]
        } else {
            (0..if planar { 2 } else { 3 })
                .map(|k| Vector3::ith(k, 1.0))
                .collect()
        };
        let axes = axes
            .into_iter()
            .map(|e| {
                start.push(d.dot(&e) / s);
                (start.len() - 1, s * e)
            })
            .collect();
        frames.push(LegFrame { axes });
    }
    Ok((frames, start))
}

//! The reduced variables of closed-curve fine tuning: one point and one
//! rotation fixed (fine-tuning paper, §4.2: "the position of at least one point
//! and rotation about at least one point of the curve should be fixed to avoid
//! rigid motion").
//!
//! - point `f`: fixed;
//! - point `f + 1`: on the ray from `C_f` along the initial leg `u` (1 variable);
//! - 3-D only: the first later point `g` whose offset from `C_f` has a part
//!   `w ⟂ u`, in the plane `C_f + span(u, w)` (2 variables);
//! - every other point: free (2 variables in the `z = const` plane of a planar
//!   curve, 3 otherwise).
//!
//! **Jacobi scaling.** Every axis of point `i` is multiplied by
//! `s_i = 1/√h_i`, `h_i` the Gauss-Newton diagonal of energy (13) at the
//! start: `h_i = 4 k_l + 2 k_a (1/l_{i−1}² + (1/l_{i−1} + 1/l_i)² + 1/l_i²)`
//! (legs `l_{i−1}`, `l_i` meet at `C_i`; `|∂θ/∂C| ≤ 1/l` for each leg). Short
//! legs make the angle terms stiff; without this nonlinear CG crawls
//! (thousands of iterations on an 8-point curve). The minimiser is unchanged.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::curve_solver::PointFrame;

/// Frames of all points and the starting variables that reproduce `points`.
pub fn variable_frames(
    points: &[Point3],
    fixed: usize,
    planar: bool,
    k_length: Real,
    k_angle: Real,
) -> Result<(Vec<PointFrame>, Vec<Real>)> {
    let n = points.len();
    if fixed >= n {
        return Err(Error::Input(format!(
            "fixed point {fixed} is out of range: the fine-tuned polygon has {n} control points"
        )));
    }
    let origin = points[fixed];
    let axis_point = (fixed + 1) % n;
    let leg = points[axis_point] - origin;
    let u = leg.try_normalize(1e-12).ok_or_else(|| {
        Error::Input(format!("the leg after fixed point {fixed} has zero length"))
    })?;
    let plane_point = if planar {
        None
    } else {
        let found = (2..n).map(|s| (fixed + s) % n).find_map(|g| {
            let off = points[g] - origin;
            (off - off.dot(&u) * u).try_normalize(1e-9).map(|w| (g, w))
        });
        Some(
            found
                .ok_or_else(|| Error::Input("the fine-tuned polygon is a straight line".into()))?,
        )
    };
    let len = |j: usize| (points[(j + 1) % n] - points[j]).norm().max(1e-12);
    let scale: Vec<Real> = (0..n)
        .map(|i| {
            let (a, b) = (1.0 / len((i + n - 1) % n), 1.0 / len(i));
            let h = 4.0 * k_length + 2.0 * k_angle * (a * a + (a + b) * (a + b) + b * b);
            1.0 / h.sqrt()
        })
        .collect();
    let mut frames = Vec::with_capacity(n);
    let mut start = Vec::with_capacity(2 * n);
    for (i, p) in points.iter().enumerate() {
        let off = p - origin;
        let s = scale[i];
        let var = |value: Real, start: &mut Vec<Real>| {
            start.push(value / s);
            start.len() - 1
        };
        let frame = if i == fixed {
            PointFrame {
                origin,
                axes: Vec::new(),
            }
        } else if i == axis_point {
            PointFrame {
                origin,
                axes: vec![(var(off.dot(&u), &mut start), s * u)],
            }
        } else if let Some((g, w)) = plane_point.filter(|(g, _)| *g == i) {
            debug_assert_eq!(g, i);
            PointFrame {
                origin,
                axes: vec![
                    (var(off.dot(&u), &mut start), s * u),
                    (var(off.dot(&w), &mut start), s * w),
                ],
            }
        } else {
            let dims = if planar { 2 } else { 3 };
            PointFrame {
                origin: Point3::new(0.0, 0.0, if planar { p.z } else { 0.0 }),
                axes: (0..dims)
                    .map(|k| (var(p[k], &mut start), Vector3::ith(k, s)))
                    .collect(),
            }
        };
        frames.push(frame);
    }
    Ok((frames, start))
}

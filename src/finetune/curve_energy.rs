//! The spring-model energy of a closed control polygon (fine-tuning paper,
//! eq. 13) and its gradient.
//!
//! `E = Σ_{i=1}^{m} k_l (l_i^opt − l_i)² + k_a (θ_i^opt − θ_i)²`
//!
//! over the `m` legs `L_i = C_{i+1} − C_i` (indices mod `m`, `l_i = |L_i|`)
//! and the `m` joints, `θ_i` being the angle between legs `i − 1` and `i` at
//! `C_i`. The optimal values come from the legs of the unclosed exact curve
//! (see `curve_exact`); the joint between its last and first legs is well
//! defined because those legs are periodic.
//!
//! **Curve form of the angle (derived; the excerpt states only eq. 13).** For
//! a planar curve (constant `z`) `θ_i` is the *signed* turning angle
//! `atan2((a × b)·ẑ, a · b)` with `a = L_{i−1}`, `b = L_i`, and `θ^opt − θ` is
//! wrapped into `(−π, π]`; its gradient is `∂θ/∂b = ẑ × b / |b|²`,
//! `∂θ/∂a = −ẑ × a / |a|²`. In 3-D only the unsigned angle
//! `atan2(|a × b|, a · b)` exists, with
//! `∂θ/∂a = −(b̂ − cos θ â) / (|a| sin θ)` (and `a ↔ b`), not defined where
//! the legs are parallel; the angle term's gradient is dropped where
//! `sin θ < 1e-9` (its size there is at most `2 k_a |θ^opt − θ| / |a|`: tiny
//! for a straight joint meant to stay straight, the common case at the
//! multiple knots; a 3-D joint meant to bend but lying straight gets no
//! push from this term).

use std::f64::consts::{PI, TAU};

use crate::math::{Point3, Real, Vector3};

/// Legs shorter than this (in the unit-square scaling) contribute no direction.
const TINY: Real = 1e-300;

/// Optimal leg lengths and joint angles of a closed polygon, and the weights.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringTargets {
    /// `l_i^opt` for leg `i` (from `C_i` to `C_{i+1}`).
    pub lengths: Vec<Real>,
    /// `θ_i^opt` at joint `i` (between legs `i − 1` and `i`).
    pub angles: Vec<Real>,
    /// Spring coefficient `k_l` of the lengths.
    pub k_length: Real,
    /// Spring coefficient `k_a` of the angles.
    pub k_angle: Real,
    /// Signed planar angles (all `z` equal) instead of unsigned 3-D angles.
    pub planar: bool,
}

/// Angle between legs `a` and `b` (signed about `+z` when `planar`).
pub fn joint_angle(a: &Vector3, b: &Vector3, planar: bool) -> Real {
    if planar {
        (a.x * b.y - a.y * b.x).atan2(a.dot(b))
    } else {
        a.cross(b).norm().atan2(a.dot(b))
    }
}

/// `(∂θ/∂a, ∂θ/∂b)` of [`joint_angle`] `θ` of legs `a`, `b` (zero for a
/// vanishing leg; in 3-D also where `sin θ < 1e-9`, see the module docs).
pub fn joint_angle_gradients(
    a: &Vector3,
    b: &Vector3,
    theta: Real,
    planar: bool,
) -> (Vector3, Vector3) {
    let (la, lb) = (a.norm(), b.norm());
    if la <= TINY || lb <= TINY {
        return (Vector3::zeros(), Vector3::zeros());
    }
    if planar {
        (
            Vector3::new(a.y, -a.x, 0.0) / (la * la),
            Vector3::new(-b.y, b.x, 0.0) / (lb * lb),
        )
    } else {
        let (ua, ub) = (a / la, b / lb);
        let (s, c) = (theta.sin(), theta.cos());
        // ∂θ/∂a · (θ − θ_opt) = −(b̂ − cos θ â)/|a| · (θ − θ_opt)/sin θ
        let ratio = if s > 1e-9 { 1.0 / s } else { 0.0 };
        (-(ub - c * ua) * ratio / la, -(ua - c * ub) * ratio / lb)
    }
}

/// `x` wrapped into `(−π, π]`.
pub fn wrap_angle(x: Real) -> Real {
    let y = x.rem_euclid(TAU);
    if y > PI { y - TAU } else { y }
}

impl SpringTargets {
    /// Targets from the legs of a polygon (periodic: leg `m − 1` is followed by leg 0).
    pub fn from_legs(legs: &[Vector3], k_length: Real, k_angle: Real, planar: bool) -> Self {
        let m = legs.len();
        SpringTargets {
            lengths: legs.iter().map(|l| l.norm()).collect(),
            angles: (0..m)
                .map(|i| joint_angle(&legs[(i + m - 1) % m], &legs[i], planar))
                .collect(),
            k_length,
            k_angle,
            planar,
        }
    }

    /// Energy (13) of the closed polygon `points`; if `gradient` is given it
    /// receives `∂E/∂C_i` (same length as `points`).
    pub fn energy(&self, points: &[Point3], mut gradient: Option<&mut [Vector3]>) -> Real {
        let m = points.len();
        if let Some(g) = gradient.as_deref_mut() {
            g.iter_mut().for_each(|v| *v = Vector3::zeros());
        }
        let leg = |i: usize| points[(i + 1) % m] - points[i];
        let mut e = 0.0;
        for i in 0..m {
            let b = leg(i);
            let lb = b.norm();
            let dl = lb - self.lengths[i];
            e += self.k_length * dl * dl;
            let a = leg((i + m - 1) % m);
            let theta = joint_angle(&a, &b, self.planar);
            let da = wrap_angle(theta - self.angles[i]);
            e += self.k_angle * da * da;
            let Some(g) = gradient.as_deref_mut() else {
                continue;
            };
            if lb > TINY {
                let f = (2.0 * self.k_length * dl / lb) * b;
                g[(i + 1) % m] += f;
                g[i] -= f;
            }
            let (ga, gb) = joint_angle_gradients(&a, &b, theta, self.planar);
            let w = 2.0 * self.k_angle * da;
            g[i] += w * ga;
            g[(i + m - 1) % m] -= w * ga;
            g[(i + 1) % m] += w * gb;
            g[i] -= w * gb;
        }
        e
    }
}

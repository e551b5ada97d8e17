//! Curvature of an unsigned 3-D angle term that the Gauss-Newton matrix
//! misses, as extra zero-valued rows for `levenberg_marquardt`.
//!
//! **Derivation.** For `θ = ∠(u, w) = atan2(|u × w|, u · w)` and a term
//! `k (θ − θ*)²`, Gauss-Newton keeps `2k ∇θ ∇θᵀ`, whose only directions are
//! in the plane of `u` and `w`. Moving `u` by `η n` and `w` by `ε n` along
//! the plane's normal `n = û × ŵ / |û × ŵ|` leaves `u · w` unchanged to first
//! order and gives `cos θ' ≈ cos θ (1 − η²/2|u|² − ε²/2|w|²) − ηε/(|u||w|)`,
//! so `∂²θ = [[cot θ/|u|², −1/(|u||w| sin θ)], [·, cot θ/|w|²]]` in `(η, ε)`.
//! For small `θ` this is `(1/θ) v vᵀ` with `v = (1/|u|, −1/|w|)` (up to
//! `O(1)`; `v` vanishes on tilting both vectors by one angle, which keeps `θ`), and the term's missing Hessian `2k (θ − θ*) ∂²θ` is
//! `2k ((θ − θ*)/θ) v vᵀ`: at a straight joint meant to stay straight
//! (`θ* ≈ 0`, the multiple knots of a curve, the loop joints of a surface)
//! exactly the isotropic bending stiffness that the in-plane row has, and the
//! reason Gauss-Newton alone crawls there. We add the row `√f (n/|u|, −n/|w|)`
//! with `f = clamp((θ − θ*)/sin θ, 0, 1)` (positive semidefinite, so the
//! model stays convex; `f ≤ 1` bounds it near `θ = π`). Where `sin θ` is
//! below `1e-9` the angle has no gradient and no normal: both directions
//! across `u` get the row with `f = 1`. The rows have residual 0, so they
//! change neither `E` nor `∇E`, only the step.

use crate::math::{Real, Vector3, perpendicular_basis};

/// Below this `sin θ` the plane of the two vectors is undefined.
const STRAIGHT: Real = 1e-9;

/// Two extra rows `(∂/∂u, ∂/∂w)` for the angle between `u` and `w` with
/// current value `theta` and target `theta_opt` (unscaled: multiply by
/// `√k`). Rows that do not apply are zero; there are always two, so the
/// sparsity pattern does not depend on the geometry.
pub fn transverse_rows(
    u: &Vector3,
    w: &Vector3,
    theta: Real,
    theta_opt: Real,
) -> [(Vector3, Vector3); 2] {
    let (lu, lw) = (u.norm(), w.norm());
    let zero = (Vector3::zeros(), Vector3::zeros());
    if lu == 0.0 || lw == 0.0 {
        return [zero, zero];
    }
    let row = |n: Vector3, f: Real| {
        let s = f.sqrt();
        (n * (s / lu), n * (-s / lw))
    };
    let sin = theta.sin();
    if sin > STRAIGHT {
        let n = u.cross(w).normalize();
        let f = ((theta - theta_opt) / sin).clamp(0.0, 1.0);
        [row(n, f), zero]
    } else {
        let [n1, n2] = perpendicular_basis(&(u / lu));
        [row(n1, 1.0), row(n2, 1.0)]
    }
}

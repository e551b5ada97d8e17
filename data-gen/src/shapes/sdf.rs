//! Signed distance primitives and a smooth union, for the implicit shapes
//! (genus 2, light bulb, anvil). Formulas after Inigo Quilez's distance
//! function catalogue (<https://iquilezles.org/articles/distfunctions/>).
//! Negative inside, positive outside.

use subdyn::math::{Point3, Real, Vector3};

/// A scalar field whose zero set is a shape's surface (negative inside).
pub type Field = dyn Fn(&Point3) -> Real + Sync;

/// Torus around the z axis through `centre`: `√((√(x²+y²) − R)² + z²) − r`.
pub fn torus(p: &Point3, centre: &Point3, major: Real, minor: Real) -> Real {
    let d = p - centre;
    let q = (d.x * d.x + d.y * d.y).sqrt() - major;
    (q * q + d.z * d.z).sqrt() - minor
}

/// Box with centre `c`, half extents `half` (outer, rounding included) and
/// edges rounded with radius `r`: `|max(q, 0)| + min(max qᵢ, 0) − r`,
/// `q = |p − c| − (half − r)`.
pub fn round_box(p: &Point3, c: &Point3, half: &Vector3, r: Real) -> Real {
    let d = p - c;
    let q = Vector3::new(
        d.x.abs() - (half.x - r),
        d.y.abs() - (half.y - r),
        d.z.abs() - (half.z - r),
    );
    let outside = Vector3::new(q.x.max(0.0), q.y.max(0.0), q.z.max(0.0)).norm();
    outside + q.x.max(q.y).max(q.z).min(0.0) - r
}

/// Cone with spherical caps: radius `r1` around `a`, `r2` around `b`, the
/// tangent cone between them (exact distance).
pub fn round_cone(p: &Point3, a: &Point3, b: &Point3, r1: Real, r2: Real) -> Real {
    let ba = b - a;
    let l2 = ba.norm_squared();
    let rr = r1 - r2;
    let a2 = l2 - rr * rr;
    let il2 = 1.0 / l2;
    let pa = p - a;
    let y = pa.dot(&ba);
    let z = y - l2;
    let x2 = (pa * l2 - ba * y).norm_squared();
    let y2 = y * y * l2;
    let z2 = z * z * l2;
    let k = rr.signum() * rr * rr * x2;
    if z.signum() * a2 * z2 > k {
        return (x2 + z2).sqrt() * il2 - r2;
    }
    if y.signum() * a2 * y2 < k {
        return (x2 + y2).sqrt() * il2 - r1;
    }
    ((x2 * a2 * il2).sqrt() + y * rr) * il2 - r1
}

/// 2-D rounded rectangle in the `(ρ, z)` half plane, centre `(0, cz)`, outer
/// half extents `(hr, hz)`, corner radius `r`.
pub fn round_rect(rho: Real, z: Real, cz: Real, hr: Real, hz: Real, r: Real) -> Real {
    let qx = rho.abs() - (hr - r);
    let qz = (z - cz).abs() - (hz - r);
    (qx.max(0.0).powi(2) + qz.max(0.0).powi(2)).sqrt() + qx.max(qz).min(0.0) - r
}

/// Smooth union `−k ln Σᵢ exp(−dᵢ / k)` (C∞; equals `min dᵢ` up to
/// `k ln n` where pieces meet, up to `k e^{−Δ/k}` at a gap `Δ` from the others).
pub fn smooth_union(d: &[Real], k: Real) -> Real {
    let m = d.iter().copied().fold(Real::INFINITY, Real::min);
    let s: Real = d.iter().map(|&di| (-(di - m) / k).exp()).sum();
    m - k * s.ln()
}

/// Central-difference gradient of `field` with step `h`.
pub fn gradient(field: &Field, p: &Point3, h: Real) -> Vector3 {
    let mut g = Vector3::zeros();
    for k in 0..3 {
        let mut a = *p;
        let mut b = *p;
        a[k] += h;
        b[k] -= h;
        g[k] = (field(&a) - field(&b)) / (2.0 * h);
    }
    g
}

/// Moves `p` onto the zero set of `field` by Newton steps along the gradient,
/// `p ← p − f ∇f / |∇f|²`, until `|f| ≤ tol` (at most 30 steps, each step
/// limited to `max_step`).
pub fn project(field: &Field, p: &Point3, h: Real, tol: Real, max_step: Real) -> Point3 {
    let mut p = *p;
    for _ in 0..30 {
        let f = field(&p);
        if f.abs() <= tol {
            break;
        }
        let g = gradient(field, &p, h);
        let g2 = g.norm_squared();
        if g2 < 1e-24 {
            break;
        }
        let mut step = g * (f / g2);
        let len = step.norm();
        if len > max_step {
            step *= max_step / len;
        }
        p -= step;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitives_are_distances_at_simple_points() {
        let o = Point3::origin();
        assert!((torus(&Point3::new(3.0, 0.0, 0.0), &o, 2.0, 0.5) - 0.5).abs() < 1e-15);
        let half = Vector3::new(1.0, 2.0, 3.0);
        assert!((round_box(&Point3::new(1.5, 0.0, 0.0), &o, &half, 0.2) - 0.5).abs() < 1e-15);
        assert!((round_box(&o, &o, &half, 0.2) + 1.0).abs() < 1e-15);
        let (a, b) = (Point3::origin(), Point3::new(0.0, 0.0, 2.0));
        // Equal radii: a capsule.
        assert!((round_cone(&Point3::new(1.0, 0.0, 1.0), &a, &b, 0.5, 0.5) - 0.5).abs() < 1e-12);
        assert!((round_cone(&Point3::new(0.0, 0.0, -1.0), &a, &b, 0.5, 0.2) - 0.5).abs() < 1e-12);
        assert!((round_rect(0.0, 0.0, 0.0, 1.0, 1.0, 0.1) + 1.0).abs() < 1e-15);
    }

    #[test]
    fn smooth_union_is_close_to_min_away_from_junctions() {
        assert!((smooth_union(&[0.0, 1.0], 0.02) - 0.0).abs() < 1e-12);
        assert!((smooth_union(&[0.3, 0.3], 0.1) - (0.3 - 0.1 * 2f64.ln())).abs() < 1e-15);
    }

    #[test]
    fn projection_lands_on_a_sphere() {
        let sphere = |p: &Point3| p.coords.norm() - 1.0;
        let q = project(&sphere, &Point3::new(0.3, 0.4, 1.7), 1e-6, 1e-14, 1.0);
        assert!((q.coords.norm() - 1.0).abs() < 1e-13);
    }
}

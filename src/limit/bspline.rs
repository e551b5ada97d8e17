//! Uniform cubic B-spline basis on `[0, 1]` and the bicubic patch weights.

use crate::math::Real;

/// Values, first and second derivatives of the four uniform cubic B-spline
/// basis functions at `t ∈ [0, 1]`:
/// `B₀ = (1−t)³/6`, `B₁ = (3t³ − 6t² + 4)/6`, `B₂ = (−3t³ + 3t² + 3t + 1)/6`, `B₃ = t³/6`.
pub fn cubic_basis(t: Real) -> [[Real; 4]; 3] {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    [
        [
            s * s * s / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ],
        [
            -0.5 * s * s,
            1.5 * t2 - 2.0 * t,
            -1.5 * t2 + t + 0.5,
            0.5 * t2,
        ],
        [s, 3.0 * t - 2.0, -3.0 * t + 1.0, t],
    ]
}

/// Tensor-product weights of the 16 control points `P[a][b]` (`a` along `s`,
/// `b` along `t`, index `4a + b`) for the value and the derivatives
/// `∂s, ∂t, ∂ss, ∂st, ∂tt` of a bicubic B-spline patch at `(s, t)`.
pub fn patch_weights(s: Real, t: Real) -> [[Real; 16]; 6] {
    let bs = cubic_basis(s);
    let bt = cubic_basis(t);
    let mut w = [[0.0; 16]; 6];
    // (derivative order in s, in t) for P, Ds, Dt, Dss, Dst, Dtt.
    let orders = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    for (k, &(ds, dt)) in orders.iter().enumerate() {
        for a in 0..4 {
            for b in 0..4 {
                w[k][4 * a + b] = bs[ds][a] * bt[dt][b];
            }
        }
    }
    w
}

/// The value row of [`patch_weights`] alone: the 16 weights of the position
/// of a bicubic B-spline patch at `(s, t)`, the same products.
pub fn position_weights(s: Real, t: Real) -> [Real; 16] {
    let [bs, ..] = cubic_basis(s);
    let [bt, ..] = cubic_basis(t);
    std::array::from_fn(|k| bs[k / 4] * bt[k % 4])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_weights_are_patch_weights_value_row() {
        for &(s, t) in &[(0.0, 0.0), (0.3, 0.7), (1.0, 0.25)] {
            assert_eq!(position_weights(s, t), patch_weights(s, t)[0]);
        }
    }

    #[test]
    fn partition_of_unity_and_derivatives() {
        for &t in &[0.0, 0.3, 0.5, 1.0] {
            let b = cubic_basis(t);
            assert!((b[0].iter().sum::<Real>() - 1.0).abs() < 1e-15);
            assert!(b[1].iter().sum::<Real>().abs() < 1e-15);
            assert!(b[2].iter().sum::<Real>().abs() < 1e-15);
            let h = 1e-6;
            let (p, m) = (cubic_basis(t + h), cubic_basis(t - h));
            for i in 0..4 {
                assert!(((p[0][i] - m[0][i]) / (2.0 * h) - b[1][i]).abs() < 1e-8);
                assert!(((p[1][i] - m[1][i]) / (2.0 * h) - b[2][i]).abs() < 1e-8);
            }
        }
    }
}

//! Intensity inhomogeneity: a smooth multiplicative bias field
//! `b(x) = 1 + A p(u) / max|p|`, `p` a random quadratic polynomial with zero mean
//! over the volume, so that `b ∈ [1 − A, 1 + A]` on the grid.

use serde::Serialize;

use crate::rng::Rng;
use crate::volume::grid::Grid;
use crate::volume::noise::{BIAS_ITEM, VOLUME_STREAM};
use crate::volume::parallel::{for_each_slice, thread_count};

/// The bias field actually applied, as written to the sidecar.
#[derive(Clone, Debug, Serialize)]
pub struct BiasField {
    /// What the numbers mean.
    pub formula: &'static str,
    /// Amplitude `A`.
    pub amplitude: f64,
    /// Coefficients of `u, v, w, uv, vw, wu, P2(u), P2(v), P2(w)`.
    pub coefficients: [f64; 9],
    /// `max |p|` over the voxel centres (the normaliser).
    pub max_abs_p: f64,
}

/// `u_i = 2 i / (n − 1) − 1` ∈ [−1, 1] along one axis (0 when n = 1).
fn unit_coords(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            if n > 1 {
                2.0 * i as f64 / (n - 1) as f64 - 1.0
            } else {
                0.0
            }
        })
        .collect()
}

/// `p(u, v, w) = Σ c_m q_m` over the nine zero-mean monomials.
fn polynomial(c: &[f64; 9], u: f64, v: f64, w: f64) -> f64 {
    let p2 = |t: f64| 0.5 * (3.0 * t * t - 1.0);
    c[0] * u
        + c[1] * v
        + c[2] * w
        + c[3] * u * v
        + c[4] * v * w
        + c[5] * w * u
        + c[6] * p2(u)
        + c[7] * p2(v)
        + c[8] * p2(w)
}

/// Multiplies `data` by the bias field of amplitude `amplitude` (0 ≤ A < 1),
/// coefficients drawn from the stream `(seed, VOLUME_STREAM, BIAS_ITEM)`. Returns the field's description,
/// or `None` when `amplitude = 0` (nothing is done).
pub fn apply_bias_field(
    data: &mut [f32],
    grid: &Grid,
    amplitude: f64,
    seed: u64,
) -> Option<BiasField> {
    if amplitude == 0.0 {
        return None;
    }
    let mut rng = Rng::for_item(seed, VOLUME_STREAM, BIAS_ITEM);
    let c: [f64; 9] = std::array::from_fn(|_| rng.gaussian());
    let [u, v, w] = grid.dims.map(unit_coords);
    let max_abs_p = max_abs_on_grid(&c, &u, &v, &w);
    let scale = if max_abs_p > 0.0 {
        amplitude / max_abs_p
    } else {
        0.0
    };
    for_each_slice(data, grid.dims, |k, slice| {
        for (j, row) in slice.chunks_mut(grid.dims[0]).enumerate() {
            for (i, x) in row.iter_mut().enumerate() {
                let b = 1.0 + scale * polynomial(&c, u[i], v[j], w[k]);
                *x = (f64::from(*x) * b) as f32;
            }
        }
    });
    Some(BiasField {
        formula: "b = 1 + amplitude * p(u,v,w) / max_abs_p; u,v,w = 2*index/(dim-1) - 1; \
                  p = c0 u + c1 v + c2 w + c3 uv + c4 vw + c5 wu + c6 P2(u) + c7 P2(v) + c8 P2(w), \
                  P2(t) = (3t^2 - 1)/2; applied before noise",
        amplitude,
        coefficients: c,
        max_abs_p,
    })
}

/// `max |p|` over all voxel centres, z slices shared among threads.
fn max_abs_on_grid(c: &[f64; 9], u: &[f64], v: &[f64], w: &[f64]) -> f64 {
    let threads = thread_count(w.len());
    let per = w.len().div_ceil(threads);
    std::thread::scope(|scope| {
        let handles: Vec<_> = w
            .chunks(per)
            .map(|ws| {
                scope.spawn(move || {
                    let mut m = 0.0f64;
                    for &wk in ws {
                        for &vj in v {
                            for &ui in u {
                                m = m.max(polynomial(c, ui, vj, wk).abs());
                            }
                        }
                    }
                    m
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or(0.0))
            .fold(0.0, f64::max)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_stays_within_one_plus_minus_a() {
        let grid = Grid::new([9, 7, 5], [1.0; 3], [0.0; 3]).unwrap();
        let mut data = vec![1.0f32; grid.len()];
        let field = apply_bias_field(&mut data, &grid, 0.3, 11).unwrap();
        let lo = data.iter().cloned().fold(f32::MAX, f32::min);
        let hi = data.iter().cloned().fold(f32::MIN, f32::max);
        assert!(lo >= 0.7 - 1e-6 && hi <= 1.3 + 1e-6, "{lo} {hi}");
        assert!((lo - 0.7).abs() < 1e-5 || (hi - 1.3).abs() < 1e-5);
        assert!(field.max_abs_p > 0.0);
    }
}

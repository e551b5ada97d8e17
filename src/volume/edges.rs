//! Edge potential `P(x) = −‖∇(G_σ * I)(x)‖` (Qin et al. 1998, §4.2).
//!
//! The paper detects 3D edges with Monga–Deriche recursive filters; subdyn
//! uses Gaussian smoothing ([`super::gaussian_smoothed`]) followed by central
//! differences, i.e. Gaussian-derivative gradients. Both estimate the
//! gradient of a smoothed image; the Gaussian is isotropic in world units
//! whatever the voxel spacing, which recursive filters are not without
//! per-axis tuning, and its cost (a few taps per axis for σ of one or two
//! voxels) is already below a second for 256³ volumes.

use rayon::prelude::*;

use super::Volume;
use crate::error::{Error, Result};
use crate::math::{Real, Vector3};

/// The potential `P = −‖∇S‖ / max ‖∇S‖` of a smoothed volume `S`, on the same
/// grid: `−1` on the strongest edge, `0` where the image is flat. Gradients
/// are central differences along the index axes (one-sided at the borders)
/// mapped to world units by `L⁻ᵀ`. Errors for a constant volume, which has
/// no edge to find.
pub fn edge_potential(smoothed: &Volume) -> Result<Volume> {
    let [nx, ny, nz] = smoothed.dims();
    let inv_t = smoothed
        .linear()
        .try_inverse()
        .map(|m| m.transpose())
        .ok_or_else(|| Error::input("singular voxel-to-world map"))?;
    let d = smoothed.data();
    let slab = nx * ny;
    let diff = |i: usize, n: usize, stride: usize, at: usize| -> Real {
        if n == 1 {
            return 0.0;
        }
        let (lo, hi, h) = if i == 0 {
            (at, at + stride, 1.0)
        } else if i == n - 1 {
            (at - stride, at, 1.0)
        } else {
            (at - stride, at + stride, 2.0)
        };
        (d[hi] as Real - d[lo] as Real) / h
    };
    let mut out = vec![0f32; d.len()];
    out.par_chunks_mut(slab).enumerate().for_each(|(k, o)| {
        for j in 0..ny {
            for i in 0..nx {
                let at = i + nx * j + slab * k;
                let g = Vector3::new(
                    diff(i, nx, 1, at),
                    diff(j, ny, nx, at),
                    diff(k, nz, slab, at),
                );
                o[i + nx * j] = (inv_t * g).norm() as f32;
            }
        }
    });
    let max = out.par_iter().cloned().reduce(|| 0.0, f32::max);
    if max.is_nan() || max <= 0.0 {
        return Err(Error::input(
            "the volume is constant: it has no edges to recover a shape from",
        ));
    }
    out.par_iter_mut().for_each(|v| *v = -*v / max);
    smoothed.with_data(out)
}

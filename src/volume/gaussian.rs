//! Separable Gaussian smoothing `G_σ * I` with σ in world units, so
//! anisotropic voxels get per-axis kernels (Qin et al. 1998, §4.2: the volume
//! is smoothed before edge detection).

use rayon::prelude::*;

use super::Volume;
use crate::error::{Error, Result};
use crate::math::Real;

/// Kernel half-width in standard deviations: the truncated tails weigh
/// below 3e-3 before renormalisation.
const TRUNCATE: Real = 3.0;

/// `G_σ * I` for a Gaussian of standard deviation `sigma` in world units
/// (millimetres for medical images). Along index axis `a` the kernel has
/// `σ_a = σ / s_a` voxels, `s_a` the axis's spacing, sampled at integer
/// offsets up to `⌈3 σ_a⌉` and normalised to sum 1; borders repeat the edge
/// sample. `sigma = 0` returns a copy. The three 1D passes run in parallel
/// and in place on the copy: the input and the result are the only
/// volumes alive.
pub fn gaussian_smoothed(volume: &Volume, sigma: Real) -> Result<Volume> {
    let kernels = kernels_of(volume, sigma)?;
    let mut data = volume.data().to_vec();
    smooth_in_place(&mut data, volume.dims(), &kernels);
    volume.with_data(data)
}

/// [`gaussian_smoothed`] in the input's own samples: the volume is given
/// up and no second one is ever allocated (for a caller that needs only
/// the smoothed image).
pub fn gaussian_smoothed_owned(volume: Volume, sigma: Real) -> Result<Volume> {
    let kernels = kernels_of(&volume, sigma)?;
    let (dims, linear, origin) = (volume.dims(), *volume.linear(), volume.origin());
    let mut data = volume.into_data();
    smooth_in_place(&mut data, dims, &kernels);
    Volume::with_affine(dims, data, linear, origin)
}

/// The per-axis kernels of `sigma` on `volume`'s grid; errors for a
/// negative or non-finite σ, or one far wider than the volume.
fn kernels_of(volume: &Volume, sigma: Real) -> Result<Vec<Vec<f32>>> {
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(Error::input(format!(
            "smoothing sigma {sigma} must be a finite length ≥ 0"
        )));
    }
    let dims = volume.dims();
    let spacing = volume.spacing();
    // The half-width is checked before a kernel is built: σ = 1e9 would
    // otherwise allocate gigabytes first.
    for a in 0..3 {
        let half = half_width(sigma / spacing[a]);
        if half > (4 * dims[a].max(64)) as Real {
            return Err(Error::input(format!(
                "smoothing sigma {sigma} spans {half:.0} voxels along axis {a}, far beyond the volume"
            )));
        }
    }
    Ok((0..3).map(|a| kernel(sigma / spacing[a])).collect())
}

/// The three 1D passes on `data` in place. Each pass copies what one task
/// reads (an x line, a z slab, or the x lines of one y across all z) into a
/// per-thread buffer and writes the result back, so no second volume is
/// ever allocated. The sums are the same, in the same order, as an
/// out-of-place pass would form them.
fn smooth_in_place(data: &mut [f32], dims: [usize; 3], kernels: &[Vec<f32>]) {
    let [nx, ny, nz] = dims;
    let slab = nx * ny;
    // x: along each line.
    if kernels[0].len() > 1 {
        let k = &kernels[0];
        data.par_chunks_mut(nx)
            .for_each_init(Vec::new, |buf: &mut Vec<f32>, row| {
                buf.clear();
                buf.extend_from_slice(row);
                convolve_line(buf, row, k);
            });
    }
    // y: whole lines combined within each slab.
    if kernels[1].len() > 1 {
        let k = &kernels[1];
        data.par_chunks_mut(slab)
            .for_each_init(Vec::new, |buf: &mut Vec<f32>, s| {
                buf.clear();
                buf.extend_from_slice(s);
                let src: &[f32] = buf;
                for j in 0..ny {
                    accumulate_rows(
                        &mut s[j * nx..(j + 1) * nx],
                        |t| {
                            let jj = (j as isize + t).clamp(0, ny as isize - 1) as usize;
                            &src[jj * nx..(jj + 1) * nx]
                        },
                        k,
                    );
                }
            });
    }
    // z: for every y, the x lines of all slabs combined.
    if kernels[2].len() > 1 {
        let k = &kernels[2];
        let mut by_y: Vec<Vec<&mut [f32]>> = (0..ny).map(|_| Vec::with_capacity(nz)).collect();
        for s in data.chunks_mut(slab) {
            for (lines, line) in by_y.iter_mut().zip(s.chunks_mut(nx)) {
                lines.push(line);
            }
        }
        by_y.par_iter_mut()
            .for_each_init(Vec::new, |buf: &mut Vec<f32>, lines| {
                buf.clear();
                for line in lines.iter() {
                    buf.extend_from_slice(line);
                }
                let src: &[f32] = buf;
                for (z, line) in lines.iter_mut().enumerate() {
                    accumulate_rows(
                        line,
                        |t| {
                            let zz = (z as isize + t).clamp(0, nz as isize - 1) as usize;
                            &src[zz * nx..(zz + 1) * nx]
                        },
                        k,
                    );
                }
            });
    }
}

/// The kernel's half-width `r = ⌈3σ⌉` (0 for σ < 0.1 voxel), as a float so
/// that an absurd σ is not cut to an integer before it is checked.
fn half_width(sigma_voxels: Real) -> Real {
    if sigma_voxels < 0.1 {
        0.0
    } else {
        (TRUNCATE * sigma_voxels).ceil()
    }
}

/// Normalised Gaussian taps at offsets `−r ..= r`, `r = ⌈3σ⌉`; `[1]` for σ < 0.1 voxel.
fn kernel(sigma_voxels: Real) -> Vec<f32> {
    if sigma_voxels < 0.1 {
        return vec![1.0];
    }
    let r = half_width(sigma_voxels) as isize;
    let w: Vec<Real> = (-r..=r)
        .map(|t| (-0.5 * (t as Real / sigma_voxels).powi(2)).exp())
        .collect();
    let sum: Real = w.iter().sum();
    w.iter().map(|x| (x / sum) as f32).collect()
}

/// `out[i] = Σ_t k_t · line[clamp(i + t)]` along a contiguous line.
fn convolve_line(line: &[f32], out: &mut [f32], k: &[f32]) {
    let n = line.len() as isize;
    let r = (k.len() / 2) as isize;
    for (i, o) in out.iter_mut().enumerate() {
        let mut s = 0f32;
        for (t, &w) in k.iter().enumerate() {
            let j = (i as isize + t as isize - r).clamp(0, n - 1) as usize;
            s += w * line[j];
        }
        *o = s;
    }
}

/// `out = Σ_t k_t · row(t − r)`: a 1D convolution across whole rows or slabs,
/// vectorised along them.
fn accumulate_rows<'a>(out: &mut [f32], row: impl Fn(isize) -> &'a [f32], k: &[f32]) {
    let r = (k.len() / 2) as isize;
    out.fill(0.0);
    for (t, &w) in k.iter().enumerate() {
        for (o, &v) in out.iter_mut().zip(row(t as isize - r)) {
            *o += w * v;
        }
    }
}

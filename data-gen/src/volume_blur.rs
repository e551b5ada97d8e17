//! Separable Gaussian blur `G_σ * I` with σ in millimetres, so that an
//! anisotropic grid is blurred by the same physical amount along every axis
//! (σ/sx, σ/sy, σ/sz voxels). Sampled kernel, truncated at 4σ, normalised to
//! sum 1; the volume is extended by repeating its border voxels.

use crate::volume::grid::Grid;
use crate::volume::parallel::{for_each_band, for_each_slice};

/// Kernels narrower than this (in voxels) are the identity.
const MIN_SIGMA_VOXELS: f64 = 1e-3;

/// Normalised Gaussian weights `w[t + r]`, `t = −r..=r`, `r = ⌈4σ⌉`; `None` for a
/// negligible σ.
pub fn gaussian_kernel(sigma_voxels: f64) -> Option<Vec<f64>> {
    if sigma_voxels < MIN_SIGMA_VOXELS {
        return None;
    }
    let r = (4.0 * sigma_voxels).ceil() as isize;
    let w: Vec<f64> = (-r..=r)
        .map(|t| (-0.5 * (t as f64 / sigma_voxels).powi(2)).exp())
        .collect();
    let sum: f64 = w.iter().sum();
    Some(w.into_iter().map(|x| x / sum).collect())
}

/// Blurs `data` in place with an isotropic Gaussian of standard deviation
/// `sigma_mm` (mm); 0 leaves it unchanged.
pub fn gaussian_blur(data: &mut [f32], grid: &Grid, sigma_mm: f64) {
    let [nx, ny, nz] = grid.dims;
    let kernels: [Option<Vec<f64>>; 3] =
        std::array::from_fn(|k| gaussian_kernel(sigma_mm / grid.spacing[k]));
    if let Some(w) = &kernels[0] {
        for_each_slice(data, grid.dims, |_, slice| {
            let mut line = vec![0.0f32; nx];
            for row in slice.chunks_mut(nx) {
                line.copy_from_slice(row);
                convolve_runs(&line, 1, nx, w, row);
            }
        });
    }
    if let Some(w) = &kernels[1] {
        for_each_slice(data, grid.dims, |_, slice| {
            let copy = slice.to_vec();
            convolve_runs(&copy, nx, ny, w, slice);
        });
    }
    if let Some(w) = &kernels[2] {
        for_each_band(data, grid.dims, |band| {
            let run = band.rows.len() * nx;
            if run == 0 {
                return;
            }
            let mut copy = Vec::with_capacity(run * nz);
            for slab in &band.slabs {
                copy.extend_from_slice(slab);
            }
            let mut acc = vec![0.0f64; run];
            for (k, slab) in band.slabs.into_iter().enumerate() {
                acc.iter_mut().for_each(|a| *a = 0.0);
                for (t, wt) in w.iter().enumerate() {
                    let src = clamped(k as isize + t as isize - (w.len() / 2) as isize, nz);
                    for (a, &x) in acc.iter_mut().zip(&copy[src * run..(src + 1) * run]) {
                        *a += wt * f64::from(x);
                    }
                }
                for (o, a) in slab.iter_mut().zip(&acc) {
                    *o = *a as f32;
                }
            }
        });
    }
}

/// `out` = `input` convolved with `w` along an axis with `n` samples whose
/// consecutive samples are runs of `run` values apart (`run = 1` for x,
/// `run = nx` for y within one slice).
fn convolve_runs(input: &[f32], run: usize, n: usize, w: &[f64], out: &mut [f32]) {
    let r = (w.len() / 2) as isize;
    let mut acc = vec![0.0f64; run];
    for j in 0..n {
        acc.iter_mut().for_each(|a| *a = 0.0);
        for (t, wt) in w.iter().enumerate() {
            let src = clamped(j as isize + t as isize - r, n);
            for (a, &x) in acc.iter_mut().zip(&input[src * run..(src + 1) * run]) {
                *a += wt * f64::from(x);
            }
        }
        for (o, a) in out[j * run..(j + 1) * run].iter_mut().zip(&acc) {
            *o = *a as f32;
        }
    }
}

/// `i` clamped to `0..n` (border voxels repeat).
fn clamped(i: isize, n: usize) -> usize {
    i.clamp(0, n as isize - 1) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_keeps_constants_and_mass_and_respects_spacing() {
        let grid = Grid::new([21, 21, 11], [1.0, 1.0, 2.0], [0.0; 3]).unwrap();
        let mut c = vec![3.0f32; grid.len()];
        gaussian_blur(&mut c, &grid, 1.5);
        assert!(c.iter().all(|&v| (v - 3.0).abs() < 1e-5));

        // A point at the centre spreads with variance σ² in mm along every axis.
        let mut d = vec![0.0f32; grid.len()];
        let centre = 10 + 21 * (10 + 21 * 5);
        d[centre] = 1.0;
        gaussian_blur(&mut d, &grid, 1.5);
        let sum: f64 = d.iter().map(|&v| f64::from(v)).sum();
        assert!((sum - 1.0).abs() < 1e-5);
        let mut var = [0.0f64; 3];
        for k in 0..11 {
            for j in 0..21 {
                for i in 0..21 {
                    let v = f64::from(d[i + 21 * (j + 21 * k)]);
                    let mm = [(i as f64 - 10.0), (j as f64 - 10.0), 2.0 * (k as f64 - 5.0)];
                    for a in 0..3 {
                        var[a] += v * mm[a] * mm[a];
                    }
                }
            }
        }
        assert!((var[0] - 2.25).abs() < 1e-3, "{var:?}");
        // Along z (2 mm voxels, σ = 0.75 voxel) the sampled kernel is a little wider.
        assert!((var[2] - 2.25).abs() < 0.05, "{var:?}");
    }
}

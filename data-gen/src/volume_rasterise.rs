//! Partial-volume rasterisation: the fraction of every voxel inside a closed
//! surface, exact along z and supersampled n × n in x, y.
//!
//! For every voxel column (i, j) and every sub-sample (x, y) of its footprint,
//! the line through (x, y) parallel to z is intersected with the surface. The
//! sorted crossings z₀ < z₁ < … pair up into inside intervals [z₀, z₁], [z₂, z₃], …
//! (even–odd rule, so orientation does not matter), and each voxel gets the
//! length of its z extent covered by them. The fraction of voxel (i, j, k) is
//! the mean of those lengths over the n² sub-samples divided by sz:
//!
//! `f(i,j,k) = 1/n² Σ_(a,b) |[z_k − sz/2, z_k + sz/2] ∩ inside(x_a, y_b)| / sz`,
//! `x_a = x_i + ((a + ½)/n − ½) sx`, likewise y_b.
//!
//! So `Σ f × sx sy sz` is the n²-point midpoint rule for the enclosed volume.
//! A line with an odd number of crossings (grazing an edge or a vertex) is
//! moved by a millionth of a voxel and cast again; the report counts those.

use std::sync::atomic::{AtomicU64, Ordering};

use serde::Serialize;

use crate::volume::grid::Grid;
use crate::volume::parallel::for_each_band;

/// A closed surface seen along lines parallel to z.
pub trait ZCrossings: Sync {
    /// Appends to `out`, in increasing order, every z at which the line
    /// `(x, y, ·)` crosses the surface.
    fn crossings(&self, x: f64, y: f64, out: &mut Vec<f64>);
}

/// What rasterisation did, for the sidecar.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RasterReport {
    /// Sub-samples per voxel along x and along y (n; n² lines per column).
    pub supersample: usize,
    /// Lines cast (one per sub-sample, without retries).
    pub lines: u64,
    /// Surface crossings found in all.
    pub crossings: u64,
    /// Lines that had an odd number of crossings and were moved and cast again.
    pub retried_lines: u64,
    /// Lines still odd after three moves; their last crossing was dropped.
    pub unresolved_lines: u64,
}

/// Fixed sub-voxel offsets (fractions of a voxel) that keep sample lines off
/// the planes and edges of meshes built on round coordinates.
const JITTER: [f64; 2] = [3.1e-7, 1.7e-7];
/// Moves tried when a line has an odd number of crossings (fractions of a voxel).
const RETRY_MOVES: [[f64; 2]; 3] = [[1.3e-6, 0.7e-6], [-0.9e-6, 1.9e-6], [2.3e-5, -1.1e-5]];

/// Inside fraction of every voxel of `grid` (x fastest), with `n × n`
/// sub-samples per voxel column.
pub fn inside_fractions(
    grid: &Grid,
    surface: &dyn ZCrossings,
    n: usize,
) -> (Vec<f32>, RasterReport) {
    let n = n.max(1);
    let [nx, _, nz] = grid.dims;
    let [sx, sy, _] = grid.spacing;
    let mut data = vec![0.0f32; grid.len()];
    let crossings_found = AtomicU64::new(0);
    let retried = AtomicU64::new(0);
    let unresolved = AtomicU64::new(0);
    for_each_band(&mut data, grid.dims, |mut band| {
        let mut zs = Vec::new();
        let mut acc = vec![0.0f64; nz];
        let (mut found, mut retries, mut failures) = (0u64, 0u64, 0u64);
        for (r, j) in band.rows.clone().enumerate() {
            for i in 0..nx {
                acc.iter_mut().for_each(|a| *a = 0.0);
                for a in 0..n {
                    for b in 0..n {
                        let u = i as f64 - 0.5 + (a as f64 + 0.5) / n as f64 + JITTER[0];
                        let v = j as f64 - 0.5 + (b as f64 + 0.5) / n as f64 + JITTER[1];
                        let line = |du: f64, dv: f64, zs: &mut Vec<f64>| {
                            zs.clear();
                            let x = grid.origin[0] + (u + du) * sx;
                            let y = grid.origin[1] + (v + dv) * sy;
                            surface.crossings(x, y, zs);
                        };
                        line(0.0, 0.0, &mut zs);
                        if zs.len() % 2 == 1 {
                            retries += 1;
                            for [du, dv] in RETRY_MOVES {
                                line(du, dv, &mut zs);
                                if zs.len() % 2 == 0 {
                                    break;
                                }
                            }
                            if zs.len() % 2 == 1 {
                                failures += 1;
                                zs.pop();
                            }
                        }
                        found += zs.len() as u64;
                        for pair in zs.chunks_exact(2) {
                            add_interval(&mut acc, grid, pair[0], pair[1]);
                        }
                    }
                }
                let norm = 1.0 / (n * n) as f64;
                for (k, slab) in band.slabs.iter_mut().enumerate() {
                    slab[r * nx + i] = (acc[k] * norm) as f32;
                }
            }
        }
        crossings_found.fetch_add(found, Ordering::Relaxed);
        retried.fetch_add(retries, Ordering::Relaxed);
        unresolved.fetch_add(failures, Ordering::Relaxed);
    });
    let report = RasterReport {
        supersample: n,
        lines: (grid.dims[0] * grid.dims[1] * n * n) as u64,
        crossings: crossings_found.into_inner(),
        retried_lines: retried.into_inner(),
        unresolved_lines: unresolved.into_inner(),
    };
    (data, report)
}

/// Adds the covered fraction of every voxel of one column for the inside
/// interval `[z0, z1]` (world z).
fn add_interval(acc: &mut [f64], grid: &Grid, z0: f64, z1: f64) {
    let nz = acc.len() as f64;
    // Voxel k covers t ∈ [k, k + 1] in these units.
    let t = |z: f64| ((z - grid.origin[2]) / grid.spacing[2] + 0.5).clamp(0.0, nz);
    let (t0, t1) = (t(z0), t(z1));
    if t1 <= t0 {
        return;
    }
    let first = t0.floor() as usize;
    let last = (t1.ceil() as usize).min(acc.len());
    for (k, a) in acc.iter_mut().enumerate().take(last).skip(first) {
        let lo = t0.max(k as f64);
        let hi = t1.min(k as f64 + 1.0);
        if hi > lo {
            *a += hi - lo;
        }
    }
}

/// An exact sphere, for checking the rasteriser against `4/3 π r³`.
#[cfg(test)]
pub struct AnalyticSphere {
    /// Centre.
    pub centre: [f64; 3],
    /// Radius.
    pub radius: f64,
}

#[cfg(test)]
impl ZCrossings for AnalyticSphere {
    fn crossings(&self, x: f64, y: f64, out: &mut Vec<f64>) {
        let d2 = self.radius.powi(2) - (x - self.centre[0]).powi(2) - (y - self.centre[1]).powi(2);
        if d2 > 0.0 {
            out.push(self.centre[2] - d2.sqrt());
            out.push(self.centre[2] + d2.sqrt());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_fractions_sum_to_its_volume() {
        let sphere = AnalyticSphere {
            centre: [0.3, -0.2, 0.1],
            radius: 5.3,
        };
        let grid = Grid::new([17, 14, 12], [0.7, 0.9, 1.1], [-5.6, -6.05, -6.05]).unwrap();
        let (f, report) = inside_fractions(&grid, &sphere, 4);
        let volume: f64 = f.iter().map(|&v| f64::from(v)).sum::<f64>() * grid.voxel_volume();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 5.3f64.powi(3);
        assert!((volume / exact - 1.0).abs() < 2e-3, "{volume} vs {exact}");
        assert!(f.iter().all(|&v| (0.0..=1.0 + 1e-6).contains(&v)));
        assert_eq!(report.unresolved_lines, 0);
        // The centre voxel is fully inside, a corner voxel fully outside.
        let centre = 8 + 17 * (7 + 14 * 6);
        assert!((f[centre] - 1.0).abs() < 1e-6);
        assert_eq!(f[0], 0.0);
    }

    #[test]
    fn one_line_is_exact_along_z() {
        let mut acc = vec![0.0; 4];
        let grid = Grid::new([1, 1, 4], [1.0, 1.0, 2.0], [0.0; 3]).unwrap();
        // Voxel k covers z ∈ [2k − 1, 2k + 1].
        add_interval(&mut acc, &grid, 0.0, 3.5);
        assert_eq!(acc, vec![0.5, 1.0, 0.25, 0.0]);
    }
}

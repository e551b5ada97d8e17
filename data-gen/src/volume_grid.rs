//! `Grid`: the voxel lattice of a volume, world = origin + index × spacing,
//! and how it is fitted around a shape's bounding box.

use anyhow::{Result, bail};

/// Largest number of voxels a volume may have (512³).
pub const MAX_VOXELS: usize = 512 * 512 * 512;

/// Largest size along one axis (NIfTI-1 stores dimensions as `i16`).
pub const MAX_DIM: usize = i16::MAX as usize;

/// Voxels along the longest axis when neither `--dims` nor `--spacing` is given.
pub const DEFAULT_LONGEST_DIM: usize = 64;

/// A regular voxel lattice. Voxel `(i, j, k)` is centred at
/// `origin + (i sx, j sy, k sz)` and covers `± spacing / 2` around it.
/// Data are stored x fastest, then y, then z: index `i + nx (j + ny k)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Number of voxels along x, y, z.
    pub dims: [usize; 3],
    /// Voxel size along x, y, z (mm).
    pub spacing: [f64; 3],
    /// World position of the centre of voxel (0, 0, 0).
    pub origin: [f64; 3],
}

impl Grid {
    /// Checks the dimensions (each ≥ 1 and ≤ [`MAX_DIM`], product ≤ [`MAX_VOXELS`]),
    /// the spacing (finite, > 0) and the origin (finite).
    pub fn new(dims: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> Result<Grid> {
        check_dims(dims)?;
        check_spacing(spacing)?;
        if origin.iter().any(|o| !o.is_finite()) {
            bail!("--origin must be finite, got {origin:?}");
        }
        Ok(Grid {
            dims,
            spacing,
            origin,
        })
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Volume of one voxel (mm³).
    pub fn voxel_volume(&self) -> f64 {
        self.spacing.iter().product()
    }
}

/// How the lattice is chosen: any of the three may be given; the rest are fitted
/// around the shape's bounding box padded by `margin` × its largest extent on
/// every side.
#[derive(Clone, Copy, Debug, Default)]
pub struct GridRequest {
    /// `--dims`.
    pub dims: Option<[usize; 3]>,
    /// `--spacing`.
    pub spacing: Option<[f64; 3]>,
    /// `--origin`.
    pub origin: Option<[f64; 3]>,
    /// `--margin`, a fraction of the bounding box's largest extent.
    pub margin: f64,
}

/// Fits a grid around the box `lo..hi`.
///
/// The box is padded by `margin × L` on every side (`L` its largest extent).
/// - dims and spacing given: used as given;
/// - dims only: isotropic spacing, the smallest for which the padded box fits;
/// - spacing only: the fewest voxels that cover the padded box;
/// - neither: isotropic, [`DEFAULT_LONGEST_DIM`] voxels along the longest axis.
///
/// Without `--origin` the voxel block is centred on the box.
pub fn fitted_grid(lo: [f64; 3], hi: [f64; 3], request: &GridRequest) -> Result<Grid> {
    if !(request.margin.is_finite() && request.margin >= 0.0) {
        bail!("--margin must be ≥ 0, got {}", request.margin);
    }
    if let Some(d) = request.dims {
        check_dims(d)?;
    }
    if let Some(s) = request.spacing {
        check_spacing(s)?;
    }
    let largest = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let pad = request.margin * largest;
    // A flat or point-like box still gets a non-zero extent.
    let floor = if largest > 0.0 { 1e-3 * largest } else { 1.0 };
    let extent: [f64; 3] = std::array::from_fn(|k| (hi[k] - lo[k] + 2.0 * pad).max(floor));
    let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let (dims, spacing) = match (request.dims, request.spacing) {
        (Some(d), Some(s)) => (d, s),
        (Some(d), None) => {
            let s = (0..3).map(|k| extent[k] / d[k] as f64).fold(0.0, f64::max);
            (d, [s; 3])
        }
        (None, Some(s)) => (std::array::from_fn(|k| covering(extent[k], s[k])), s),
        (None, None) => {
            let s = extent.iter().fold(0.0_f64, |a, &e| a.max(e)) / DEFAULT_LONGEST_DIM as f64;
            (std::array::from_fn(|k| covering(extent[k], s)), [s; 3])
        }
    };
    let origin = request.origin.unwrap_or(std::array::from_fn(|k| {
        centre[k] - 0.5 * (dims[k] as f64 - 1.0) * spacing[k]
    }));
    Grid::new(dims, spacing, origin)
}

/// Fewest voxels of size `s` that cover `extent` (at least 1; saturates so that
/// an absurd request fails the size check instead of overflowing).
fn covering(extent: f64, s: f64) -> usize {
    let n = (extent / s - 1e-9).ceil();
    if n >= usize::MAX as f64 / 2.0 {
        usize::MAX / 2
    } else {
        (n as usize).max(1)
    }
}

fn check_dims(d: [usize; 3]) -> Result<()> {
    if d.contains(&0) {
        bail!("--dims must be at least 1 along every axis, got {d:?}");
    }
    if let Some(&big) = d.iter().find(|&&n| n > MAX_DIM) {
        bail!("--dims {d:?}: {big} voxels along one axis is more than the limit of {MAX_DIM}");
    }
    let total = d.iter().try_fold(1usize, |a, &n| a.checked_mul(n));
    match total {
        Some(t) if t <= MAX_VOXELS => Ok(()),
        _ => bail!(
            "volume of {}×{}×{} voxels is more than the limit of 512³ = {MAX_VOXELS}; use larger --spacing or smaller --dims",
            d[0],
            d[1],
            d[2]
        ),
    }
}

fn check_spacing(s: [f64; 3]) -> Result<()> {
    if s.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        bail!("--spacing must be finite and > 0 along every axis, got {s:?}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_grid_is_isotropic_and_centred() {
        let req = GridRequest {
            margin: 0.1,
            ..Default::default()
        };
        let g = fitted_grid([-1.0, -2.0, -0.5], [1.0, 2.0, 0.5], &req).unwrap();
        assert_eq!(g.dims[1], DEFAULT_LONGEST_DIM);
        assert_eq!(g.spacing[0], g.spacing[2]);
        for k in 0..3 {
            let mid = g.origin[k] + 0.5 * (g.dims[k] - 1) as f64 * g.spacing[k];
            assert!(mid.abs() < 1e-12);
        }
    }

    #[test]
    fn spacing_only_covers_the_padded_box() {
        let req = GridRequest {
            spacing: Some([0.5, 0.5, 2.0]),
            margin: 0.0,
            ..Default::default()
        };
        let g = fitted_grid([0.0; 3], [4.0; 3], &req).unwrap();
        assert_eq!(g.dims, [8, 8, 2]);
    }

    #[test]
    fn bad_requests_fail() {
        assert!(Grid::new([0, 4, 4], [1.0; 3], [0.0; 3]).is_err());
        assert!(Grid::new([600, 600, 600], [1.0; 3], [0.0; 3]).is_err());
        assert!(Grid::new([4, 4, 4], [1.0, -1.0, 1.0], [0.0; 3]).is_err());
    }
}

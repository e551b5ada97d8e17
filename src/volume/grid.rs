//! [`Volume`]: a scalar image on a regular 3D grid with its voxel-to-world map.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use nalgebra::Matrix3;

/// A scalar volume: `dims[0] × dims[1] × dims[2]` samples stored x fastest,
/// then y, then z (`data[i + nx (j + ny k)]`), with the affine map from voxel
/// index to world coordinates (millimetres for medical images):
///
/// `world = origin + L · (i, j, k)ᵀ`,
///
/// where `L` (the `linear` matrix) has the voxel spacing on its diagonal for
/// axis-aligned grids and carries rotations for NIfTI qform/sform volumes.
/// Sample values sit at voxel centres, so index `(0, 0, 0)` is at `origin`.
#[derive(Clone, Debug)]
pub struct Volume {
    dims: [usize; 3],
    data: Vec<f32>,
    origin: Point3,
    linear: Matrix3<Real>,
    inverse: Matrix3<Real>,
}

impl Volume {
    /// An axis-aligned volume: `world = origin + (i sx, j sy, k sz)`.
    pub fn new(
        dims: [usize; 3],
        data: Vec<f32>,
        spacing: [Real; 3],
        origin: Point3,
    ) -> Result<Self> {
        let linear = Matrix3::from_diagonal(&Vector3::new(spacing[0], spacing[1], spacing[2]));
        Self::with_affine(dims, data, linear, origin)
    }

    /// A volume with a general voxel-to-world map `world = origin + linear · index`.
    /// Errors when the dimensions and data disagree, a dimension is zero, the
    /// map is singular or not finite, or a sample is NaN or infinite.
    pub fn with_affine(
        dims: [usize; 3],
        data: Vec<f32>,
        linear: Matrix3<Real>,
        origin: Point3,
    ) -> Result<Self> {
        if dims.contains(&0) {
            return Err(Error::input(format!(
                "volume dimensions {}×{}×{} contain a zero",
                dims[0], dims[1], dims[2]
            )));
        }
        let n = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .ok_or_else(|| Error::input("volume dimensions overflow"))?;
        if n != data.len() {
            return Err(Error::input(format!(
                "volume of {}×{}×{} = {n} voxels given {} samples",
                dims[0],
                dims[1],
                dims[2],
                data.len()
            )));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(format!(
                "voxel {i} (x {}, y {}, z {}) is {}: volumes must be finite",
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
                data[i]
            )));
        }
        if !(linear.iter().all(|v| v.is_finite()) && origin.iter().all(|v| v.is_finite())) {
            return Err(Error::non_finite("the voxel-to-world map is not finite"));
        }
        let inverse = linear
            .try_inverse()
            .filter(|m| m.iter().all(|v| v.is_finite()))
            .ok_or_else(|| Error::input("the voxel-to-world map is singular (a zero spacing?)"))?;
        Ok(Volume {
            dims,
            data,
            origin,
            linear,
            inverse,
        })
    }

    /// Samples per axis `[nx, ny, nz]`.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The samples, x fastest.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The samples, giving up the volume (x fastest).
    pub fn into_data(self) -> Vec<f32> {
        self.data
    }

    /// A volume on the same grid with other samples.
    pub fn with_data(&self, data: Vec<f32>) -> Result<Self> {
        Self::with_affine(self.dims, data, self.linear, self.origin)
    }

    /// World position of voxel index `(0, 0, 0)`.
    pub fn origin(&self) -> Point3 {
        self.origin
    }

    /// The linear part `L` of the voxel-to-world map.
    pub fn linear(&self) -> &Matrix3<Real> {
        &self.linear
    }

    /// Length of each index axis in world units: the columns' norms of `L`.
    pub fn spacing(&self) -> [Real; 3] {
        [0, 1, 2].map(|c| self.linear.column(c).norm())
    }

    /// The smallest spacing: the length "one voxel" in the reports.
    pub fn voxel_size(&self) -> Real {
        let s = self.spacing();
        s[0].min(s[1]).min(s[2])
    }

    /// Linear index of voxel `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Voxel `(i, j, k)` of linear index `n` (the inverse of [`index`](Self::index)).
    #[inline]
    pub fn voxel(&self, n: usize) -> [usize; 3] {
        let d = self.dims;
        [n % d[0], (n / d[0]) % d[1], n / (d[0] * d[1])]
    }

    /// Linear index of voxel `v + d`, or `None` outside the grid.
    #[inline]
    pub fn offset_index(&self, v: [usize; 3], d: [isize; 3]) -> Option<usize> {
        let w = [0, 1, 2].map(|a| v[a] as isize + d[a]);
        (0..3)
            .all(|a| w[a] >= 0 && w[a] < self.dims[a] as isize)
            .then(|| self.index(w[0] as usize, w[1] as usize, w[2] as usize))
    }

    /// The sample at voxel `(i, j, k)` (panics out of range, like slice indexing).
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        self.data[self.index(i, j, k)]
    }

    /// World position of a (possibly fractional) voxel index.
    pub fn world(&self, index: [Real; 3]) -> Point3 {
        self.origin + self.linear * Vector3::from(index)
    }

    /// Fractional voxel index of a world position.
    pub fn continuous_index(&self, p: &Point3) -> [Real; 3] {
        let v = self.inverse * (p - self.origin);
        [v.x, v.y, v.z]
    }

    /// A world-space vector in index units (`L⁻¹ v`).
    pub fn index_vector(&self, v: &Vector3) -> [Real; 3] {
        let c = self.inverse * v;
        [c.x, c.y, c.z]
    }

    /// Whether a world position lies inside the grid's sample box
    /// (`0 ≤ index ≤ n − 1` on every axis).
    pub fn contains(&self, p: &Point3) -> bool {
        let c = self.continuous_index(p);
        (0..3).all(|a| c[a] >= 0.0 && c[a] <= (self.dims[a] - 1) as Real)
    }

    /// World-space corners of the sample box (lowest and highest corner of
    /// the axis-aligned box around the eight corner samples).
    pub fn world_bounds(&self) -> (Point3, Point3) {
        let hi = self.dims.map(|d| (d - 1) as Real);
        let mut lo_p = Point3::from([Real::INFINITY; 3]);
        let mut hi_p = Point3::from([Real::NEG_INFINITY; 3]);
        for c in 0..8 {
            let idx = [0, 1, 2].map(|a| if c >> a & 1 == 1 { hi[a] } else { 0.0 });
            let w = self.world(idx);
            for a in 0..3 {
                lo_p[a] = lo_p[a].min(w[a]);
                hi_p[a] = hi_p[a].max(w[a]);
            }
        }
        (lo_p, hi_p)
    }

    /// Lowest and highest sample.
    pub fn range(&self) -> (f32, f32) {
        self.data
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    }

    /// Trilinear interpolation at a world position; positions outside the
    /// grid take the value of the nearest border sample (clamped index).
    pub fn sample(&self, p: &Point3) -> Real {
        self.sample_index(self.continuous_index(p))
    }

    /// Trilinear interpolation at a fractional voxel index (clamped to the grid).
    pub fn sample_index(&self, c: [Real; 3]) -> Real {
        let mut base = [0usize; 3];
        let mut frac = [0.0; 3];
        for a in 0..3 {
            let n = self.dims[a];
            let x = c[a].clamp(0.0, (n - 1) as Real);
            let i = (x.floor() as usize).min(n.saturating_sub(2));
            base[a] = i;
            frac[a] = if n > 1 { x - i as Real } else { 0.0 };
        }
        let step = [
            usize::from(self.dims[0] > 1),
            usize::from(self.dims[1] > 1) * self.dims[0],
            usize::from(self.dims[2] > 1) * self.dims[0] * self.dims[1],
        ];
        let i0 = self.index(base[0], base[1], base[2]);
        let mut v = 0.0;
        for c in 0..8 {
            let mut w = 1.0;
            let mut i = i0;
            for a in 0..3 {
                if c >> a & 1 == 1 {
                    w *= frac[a];
                    i += step[a];
                } else {
                    w *= 1.0 - frac[a];
                }
            }
            if w != 0.0 {
                v += w * self.data[i] as Real;
            }
        }
        v
    }

    /// World-space gradient of the trilinear interpolant by central
    /// differences of half a voxel along each index axis, mapped through
    /// `L⁻ᵀ` (the chain rule for `index = L⁻¹ (world − origin)`).
    pub fn gradient(&self, p: &Point3) -> Vector3 {
        let c = self.continuous_index(p);
        let mut g = Vector3::zeros();
        for a in 0..3 {
            let (mut lo, mut hi) = (c, c);
            lo[a] -= 0.5;
            hi[a] += 0.5;
            g[a] = self.sample_index(hi) - self.sample_index(lo);
        }
        self.inverse.transpose() * g
    }
}

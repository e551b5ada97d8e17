//! Principal axes of a point cloud (PCA), with the input checks every
//! initial-model builder shares.
//!
//! `C = 1/n Σ (p − c)(p − c)ᵀ`, `C a_k = λ_k a_k`, `λ_0 ≥ λ_1 ≥ λ_2`; the
//! eigenvectors come from nalgebra's `SymmetricEigen` (Jacobi-free QR on a
//! 3×3 symmetric matrix) and are made right-handed, `a_2 = a_0 × a_1`.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, first_non_finite};

/// Fewest points accepted by [`super::initial_mesh`].
pub const MIN_POINTS: usize = 10;

/// Relative extent below which an axis counts as flat: the second axis of a
/// collinear cloud, every axis of a single repeated point.
const DEGENERATE: Real = 1e-9;

/// Centroid, principal axes and extents of a point cloud.
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipalFrame {
    /// Mean of the points `c`.
    pub centroid: Point3,
    /// Unit axes `a_0, a_1, a_2` by decreasing variance, right-handed.
    pub axes: [Vector3; 3],
    /// Variances `λ_k` along the axes.
    pub variances: [Real; 3],
    /// Smallest local coordinate `(p − c)·a_k` over the points.
    pub lo: [Real; 3],
    /// Largest local coordinate `(p − c)·a_k` over the points.
    pub hi: [Real; 3],
}

impl PrincipalFrame {
    /// Checks the points (see [`check_points`]) and computes their frame;
    /// collinear or identical points are an [`Error::Input`].
    pub fn from_points(points: &[Point3]) -> Result<PrincipalFrame> {
        check_points(points)?;
        let n = points.len() as Real;
        let centroid = Point3::from(points.iter().map(|p| p.coords).sum::<Vector3>() / n);
        let mut cov = nalgebra::Matrix3::<Real>::zeros();
        for p in points {
            let d = p - centroid;
            cov += d * d.transpose();
        }
        cov /= n;
        let eig = nalgebra::SymmetricEigen::new(cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
        let axis = |k: usize| -> Vector3 {
            let a: Vector3 = eig.eigenvectors.column(order[k]).into_owned().normalize();
            // Fix the arbitrary sign: the largest component is positive.
            let big = a.iamax();
            if a[big] < 0.0 { -a } else { a }
        };
        let (a0, a1) = (axis(0), axis(1));
        let a2 = a0.cross(&a1).normalize();
        let a1 = a2.cross(&a0);
        let mut frame = PrincipalFrame {
            centroid,
            axes: [a0, a1, a2],
            variances: [0, 1, 2].map(|k| eig.eigenvalues[order[k]].max(0.0)),
            lo: [Real::INFINITY; 3],
            hi: [Real::NEG_INFINITY; 3],
        };
        for p in points {
            let l = frame.local(p);
            for k in 0..3 {
                frame.lo[k] = frame.lo[k].min(l[k]);
                frame.hi[k] = frame.hi[k].max(l[k]);
            }
        }
        let scale = centroid.coords.amax().max(1.0);
        let ext = frame.extents();
        let widest = ext[0].max(ext[1]).max(ext[2]);
        if widest <= DEGENERATE * scale {
            return Err(Error::input(format!(
                "all {} points are identical (at {:.6}, {:.6}, {:.6}); an initial model needs a spread of points",
                points.len(),
                centroid.x,
                centroid.y,
                centroid.z
            )));
        }
        let mut sorted = ext;
        sorted.sort_by(|a, b| b.total_cmp(a));
        if sorted[1] <= DEGENERATE * widest {
            return Err(Error::input(format!(
                "the {} points are collinear (extent {widest:.6e} along their line, {:.3e} across it); \
                 an initial model needs points spread over a surface",
                points.len(),
                sorted[1]
            )));
        }
        Ok(frame)
    }

    /// Local coordinates `((p − c)·a_0, (p − c)·a_1, (p − c)·a_2)`.
    pub fn local(&self, p: &Point3) -> Vector3 {
        let d = p - self.centroid;
        Vector3::new(
            d.dot(&self.axes[0]),
            d.dot(&self.axes[1]),
            d.dot(&self.axes[2]),
        )
    }

    /// The point with local coordinates `l`: `c + Σ l_k a_k`.
    pub fn world(&self, l: &Vector3) -> Point3 {
        self.centroid + self.axes[0] * l[0] + self.axes[1] * l[1] + self.axes[2] * l[2]
    }

    /// Extents `hi_k − lo_k` along the three axes.
    pub fn extents(&self) -> [Real; 3] {
        [0, 1, 2].map(|k| self.hi[k] - self.lo[k])
    }

    /// The same frame turned half a turn about `a_0` (`a_1 → −a_1`,
    /// `a_2 → −a_2`), still right-handed.
    pub fn flipped(&self) -> PrincipalFrame {
        PrincipalFrame {
            centroid: self.centroid,
            axes: [self.axes[0], -self.axes[1], -self.axes[2]],
            variances: self.variances,
            lo: [self.lo[0], -self.hi[1], -self.hi[2]],
            hi: [self.hi[0], -self.lo[1], -self.lo[2]],
        }
    }
}

/// The checks shared by every builder: at least [`MIN_POINTS`] points, all
/// coordinates finite. Errors are [`Error::Input`] naming the problem.
pub fn check_points(points: &[Point3]) -> Result<()> {
    if points.is_empty() {
        return Err(Error::input(
            "the point cloud is empty; an initial model needs points",
        ));
    }
    if let Some(i) = first_non_finite(points) {
        let bad = points
            .iter()
            .filter(|p| !p.coords.iter().all(|c| c.is_finite()))
            .count();
        return Err(Error::non_finite(format!(
            "point {i} has a non-finite coordinate ({}, {}, {}); {bad} of {} points are not finite",
            points[i].x,
            points[i].y,
            points[i].z,
            points.len()
        )));
    }
    if points.len() < MIN_POINTS {
        return Err(Error::input(format!(
            "only {} points; an initial model needs at least {MIN_POINTS}",
            points.len()
        )));
    }
    Ok(())
}

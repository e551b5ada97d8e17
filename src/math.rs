//! Scalar and small vector types shared by every module, and tolerances.

/// The scalar type of all geometry: positions, weights, energies.
pub type Real = f64;
/// A point in 3-space.
pub type Point3 = nalgebra::Point3<Real>;
/// A vector in 3-space.
pub type Vector3 = nalgebra::Vector3<Real>;

/// Relative tolerance used when comparing geometry against references.
pub const REL_TOL: Real = 1e-9;

/// Most parts a parallel sum is split into (see [`reduction_parts`]).
pub const MAX_REDUCTION_PARTS: usize = 8;

/// How many parts to split `n` items of a parallel sum into, each with its
/// own accumulator: one per `min_per_part` items, at least one, at most
/// [`MAX_REDUCTION_PARTS`]. The count depends on the problem only, never on
/// the number of threads, and the parts are then added in order, so a sum
/// gives the same bits on any thread count.
///
/// ```
/// use subdyn::math::reduction_parts;
/// assert_eq!(reduction_parts(0, 100), 1);
/// assert_eq!(reduction_parts(250, 100), 3);
/// assert_eq!(reduction_parts(1 << 30, 100), 8);
/// ```
pub fn reduction_parts(n: usize, min_per_part: usize) -> usize {
    n.div_ceil(min_per_part.max(1))
        .clamp(1, MAX_REDUCTION_PARTS)
}

/// Axis-aligned bounding box of a set of points; `None` for an empty set.
pub fn bounding_box(points: &[Point3]) -> Option<(Point3, Point3)> {
    let first = points.first()?;
    let mut lo = *first;
    let mut hi = *first;
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Some((lo, hi))
}

/// The index of the first point with a NaN or infinite coordinate.
pub fn first_non_finite(points: &[Point3]) -> Option<usize> {
    points
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
}

/// Length of the bounding-box diagonal (0 for an empty or single-point set).
pub fn bbox_diagonal(points: &[Point3]) -> Real {
    bounding_box(points).map_or(0.0, |(lo, hi)| (hi - lo).norm())
}

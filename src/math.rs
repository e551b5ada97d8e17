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

/// Twice the vector area of the polygon `face` (indices into `positions`),
/// by Newell's method: `Σ (y_i − y_j)(z_i + z_j), …` over its edges `i → j`.
/// Its direction is the polygon's best-fit normal (right-handed with the
/// vertex order), also for a non-planar polygon; zero for a degenerate one
/// (Sutherland, Sproull and Schumacker, "A characterization of ten
/// hidden-surface algorithms", *ACM Computing Surveys* 6(1), 1974).
pub fn newell_normal(positions: &[Point3], face: &[u32]) -> Vector3 {
    let mut n = Vector3::zeros();
    for (i, &a) in face.iter().enumerate() {
        let (p, q) = (
            positions[a as usize],
            positions[face[(i + 1) % face.len()] as usize],
        );
        n += Vector3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    n
}

/// Whether the polygon `face` folds over itself: projected onto its
/// [`newell_normal`] plane, two of its edges that do not share a corner
/// cross, or it has no area. Such a face has no triangulation in its plane
/// (ear clipping fails on it), which is how triangle-mesh readers such as
/// Open3D's treat a polygon; a bow-tie quad is the simplest case.
///
/// ```
/// use subdyn::math::{Point3, polygon_folds};
/// let p = |x, y, z| Point3::new(x, y, z);
/// // A non-convex L-shaped hexagon does not fold, nor does a saddle quad.
/// let l = [p(0., 0., 0.), p(2., 0., 0.), p(2., 1., 0.), p(1., 1., 0.), p(1., 2., 0.), p(0., 2., 0.)];
/// assert!(!polygon_folds(&l, &[0, 1, 2, 3, 4, 5]));
/// let saddle = [p(0., 0., 0.), p(1., 0., 0.3), p(1., 1., 0.), p(0., 1., 0.3)];
/// assert!(!polygon_folds(&saddle, &[0, 1, 2, 3]));
/// // Two corners of a square swapped: a bow tie, edges 0–1 and 2–3 cross.
/// let bow = [p(0., 0., 0.), p(1., 1., 0.1), p(1., 0., 0.), p(0., 1., 0.1)];
/// assert!(polygon_folds(&bow, &[0, 1, 2, 3]));
/// // A polygon with no area (all corners on a line).
/// let line = [p(0., 0., 0.), p(1., 0., 0.), p(2., 0., 0.)];
/// assert!(polygon_folds(&line, &[0, 1, 2]));
/// ```
pub fn polygon_folds(positions: &[Point3], face: &[u32]) -> bool {
    let n = newell_normal(positions, face);
    let Some(n) = n.try_normalize(0.0) else {
        return true;
    };
    let [u, w] = perpendicular_basis(&n);
    let q: Vec<[Real; 2]> = face
        .iter()
        .map(|&a| {
            let p = positions[a as usize].coords;
            [p.dot(&u), p.dot(&w)]
        })
        .collect();
    let side = |o: [Real; 2], a: [Real; 2], b: [Real; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let k = q.len();
    (0..k).any(|i| {
        (i + 2..k).filter(|&j| (j + 1) % k != i).any(|j| {
            let (a, b, c, d) = (q[i], q[(i + 1) % k], q[j], q[(j + 1) % k]);
            side(c, d, a) * side(c, d, b) < 0.0 && side(a, b, c) * side(a, b, d) < 0.0
        })
    })
}

/// Two unit vectors that make a right-handed orthonormal frame with the unit
/// vector `d`: `e1 = d × h / |d × h|` with `h` the x axis (the y axis when
/// `d` is within about 25° of x), and `e2 = d × e1`.
pub fn perpendicular_basis(d: &Vector3) -> [Vector3; 2] {
    let helper = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = d.cross(&helper).normalize();
    [e1, d.cross(&e1)]
}

/// Groups `pairs` `(key, item)`, every `key < n`, in compressed-row form (a
/// stable counting sort; the transposition of Gustavson, ACM TOMS 4(3),
/// 1978): returns the offsets (`n + 1` of them) and the
/// items, those of key `k` at `items[offsets[k]..offsets[k + 1]]` in the
/// order `pairs` gives them.
pub fn group_by_key<T: Copy + Default>(
    n: usize,
    pairs: impl Iterator<Item = (usize, T)> + Clone,
) -> (Vec<usize>, Vec<T>) {
    let mut offsets = vec![0usize; n + 1];
    for (k, _) in pairs.clone() {
        offsets[k + 1] += 1;
    }
    for k in 0..n {
        offsets[k + 1] += offsets[k];
    }
    let mut fill = offsets.clone();
    let mut items = vec![T::default(); offsets[n]];
    for (k, t) in pairs {
        items[fill[k]] = t;
        fill[k] += 1;
    }
    (offsets, items)
}

/// Offsets of a relation whose items are `u32` indices, as `u32`.
pub(crate) fn u32_offsets(offsets: Vec<usize>) -> Vec<u32> {
    offsets.into_iter().map(|o| o as u32).collect()
}

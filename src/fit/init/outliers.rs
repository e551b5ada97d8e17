//! Statistical outlier removal before building an initial model.
//!
//! Stray points (scanner noise far from the surface, clutter) would stretch
//! the principal-axes extents of the ellipsoid cage and the open grid, and
//! block the holes of the occupancy cage. With `d_8(p)` the distance from
//! `p` to its 8th nearest neighbour and `m` its median over the cloud, a
//! point is an outlier when
//!
//! 1. it is isolated, `d_8(p) > 3 m` (the "statistical outlier removal" of
//!    PCL and Open3D, with a median for robustness). Uniform outliers in the
//!    bounding box of the data-gen scans are about eight times further apart
//!    than the surface samples; surface samples stay within the factor except
//!    at sparse rims and grazing angles of single views (0.2 % of `bun045`,
//!    1–2 % of 2,000-point single views, none of the 8-view scans), which
//!    costs the coarse cage nothing; or
//! 2. it is off the surface its neighbours describe: its distance to the
//!    least-squares plane of its 8 neighbours exceeds `4 max(σ, 1.5 σ̃) + m / 4`,
//!    where `σ` is the RMS distance of the neighbours themselves from that
//!    plane and `σ̃` the median of `σ` over the cloud (the noise level; a
//!    6-point fit underestimates it by about 1/0.7, and the floor keeps noisy
//!    points whose few neighbours happen to be flat). This removes the
//!    outliers that test 1 keeps because they lie close enough to the surface
//!    to have surface points as neighbours. On a smooth surface a
//!    sample's offset is at the noise level, which `σ` measures; at an edge or
//!    a corner `σ` grows with the neighbours' spread, so features are kept.
//!    The plane is refitted without its two worst neighbours (so a few
//!    nearby outliers cannot shelter each other); neighbours along a line (a
//!    scan line) define no plane and skip the test. Near a crease that plane
//!    can follow the sheet holding most neighbours (or, on a bend sampled in
//!    rows, skip the middle row), so a point off it is kept when the
//!    neighbours the trim left out are off it alike ([`shares_a_sheet`]).
//!    Points on sharp edges are data, not outliers.

use super::sampling::point_tree;
use crate::math::{Point3, Real, Vector3};
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use std::num::NonZero;

/// Neighbour whose distance is the statistic.
const K: usize = 8;

/// Neighbours left out of the refitted plane.
const TRIM: usize = 2;

/// Isolated when `d_8` exceeds this multiple of its median `m`.
pub const ISOLATION_FACTOR: Real = 3.0;

/// Off the surface when the offset from the neighbours' plane exceeds
/// `OFFSET_SIGMAS max(σ, NOISE_FLOOR σ̃) + OFFSET_SLACK m`.
pub const OFFSET_SIGMAS: Real = 4.0;

/// See [`OFFSET_SIGMAS`].
pub const NOISE_FLOOR: Real = 1.5;

/// See [`OFFSET_SIGMAS`].
pub const OFFSET_SLACK: Real = 0.25;

/// With Gaussian noise `σ` along the normal, a plane fitted to 8 points
/// leaves `8 r² ~ σ² χ²₅` (3 of the 8 degrees of freedom go to the plane),
/// and the median of `√(χ²₅ / 5)` is 0.933, so `σ ≈ median r · √(8/5) / 0.933`.
pub const UNTRIMMED_TO_NOISE: Real = 1.355_9;

/// Passes of the two tests: an outlier next to another one can tilt its
/// neighbours' plane and survive the first pass, not the second.
const PASSES: usize = 2;

/// A further pass runs only when the previous one dropped more than this
/// fraction of the points (clean scans lose a handful and stop after one).
const REPASS_FRACTION: Real = 0.005;

/// A cloud's outlier screening ([`screen`]). The initial model and the fit
/// screen the same cloud: [`super::initial_mesh`] reports its screening so
/// that the fit ([`crate::fit::fit_screened_cloud`]) need not repeat it.
#[derive(Clone, Debug, PartialEq)]
pub struct Screening {
    /// True for the points to keep.
    pub keep: Vec<bool>,
    /// The noise level of the first pass (0 when it cannot be told).
    pub noise: Real,
}

/// The points to keep (up to two passes of the tests of the module docs,
/// each on the points kept by the previous one) and the noise level of the
/// first pass: the median over the cloud of the 8 neighbours' RMS offset `r`
/// from their (untrimmed) least-squares plane, times [`UNTRIMMED_TO_NOISE`];
/// 0 when the cloud is too small or too degenerate to tell. Curvature within
/// a neighbourhood adds to it, so on coarsely sampled curved surfaces it
/// overestimates the noise.
pub fn screen(points: &[Point3]) -> Screening {
    let mut keep = vec![true; points.len()];
    let mut noise = None;
    for _ in 0..PASSES {
        let index: Vec<usize> = (0..points.len()).filter(|&i| keep[i]).collect();
        let subset: Vec<Point3> = index.iter().map(|&i| points[i]).collect();
        let (pass, sigma) = one_pass(&subset);
        noise.get_or_insert(sigma);
        let dropped = pass.iter().filter(|&&k| !k).count();
        if dropped == 0 {
            break;
        }
        for (&i, k) in index.iter().zip(pass) {
            keep[i] = k;
        }
        if (dropped as Real) <= REPASS_FRACTION * index.len() as Real {
            break;
        }
    }
    Screening {
        keep,
        noise: noise.unwrap_or(0.0),
    }
}

/// One pass of the tests and `σ̃`; clouds with at most `K + 1` points keep
/// everything.
fn one_pass(points: &[Point3]) -> (Vec<bool>, Real) {
    if points.len() <= K + 1 {
        return (vec![true; points.len()], 0.0);
    }
    let tree = point_tree(points);
    let k = NonZero::new(K + 1).unwrap_or(NonZero::<usize>::MIN);
    let neighbours = |p: &Point3| -> (Real, Vec<Vector3>) {
        let near = tree.nearest_n::<SquaredEuclidean>(&[p.x, p.y, p.z], k);
        let d8 = near.last().map_or(0.0, |nn| nn.distance.sqrt());
        let others = near
            .iter()
            .skip(1)
            .map(|nn| points[nn.item as usize].coords)
            .collect();
        (d8, others)
    };
    // Per point: d_8, the offset from the plane of the 8 neighbours, their
    // RMS offset σ (trimmed refit) and their RMS offset from the untrimmed fit.
    let stats: Vec<(Real, Real, Real, Real)> = points
        .par_iter()
        .map(|p| {
            let (d8, others) = neighbours(p);
            let fit = plane_offset(&p.coords, &others);
            (d8, fit.offset, fit.sigma, fit.untrimmed)
        })
        .collect();
    let mut d8: Vec<Real> = stats.iter().map(|s| s.0).collect();
    let mid = d8.len() / 2;
    d8.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let m = d8[mid];
    if m <= 0.0 {
        // Mostly repeated points: no scale to judge by.
        return (vec![true; points.len()], 0.0);
    }
    let median = |i: fn(&(Real, Real, Real, Real)) -> Real| {
        let mut v: Vec<Real> = stats.iter().map(i).collect();
        *v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
    };
    let floor = NOISE_FLOOR * median(|s| s.2);
    let noise = median(|s| s.3) * UNTRIMMED_TO_NOISE;
    let limit = |sigma: Real| OFFSET_SIGMAS * sigma.max(floor) + OFFSET_SLACK * m;
    let keep = points
        .par_iter()
        .zip(&stats)
        .map(|(p, &(d, offset, sigma, _))| {
            if d > ISOLATION_FACTOR * m {
                return false;
            }
            if offset <= limit(sigma) {
                return true;
            }
            // Off its neighbours' plane: still a sample when it is one of a
            // row of samples off it (a crease or a coarsely sampled bend).
            let (_, others) = neighbours(p);
            shares_a_sheet(&p.coords, &others, limit)
        })
        .collect();
    (keep, noise)
}

/// The least-squares plane of a point's neighbours, as [`plane_offset`] fits it.
struct PlaneFit {
    /// Distance from the point to the trimmed plane.
    offset: Real,
    /// RMS distance of the kept neighbours from the trimmed plane.
    sigma: Real,
    /// RMS distance of all neighbours from the untrimmed plane.
    untrimmed: Real,
    /// Centroid and unit normal of the trimmed plane (`None`: no plane).
    plane: Option<(Vector3, Vector3)>,
}

/// Distance from `p` to the least-squares plane of `others` and the RMS
/// distance `σ` of `others` from it. The plane is fitted twice, the second
/// time without the [`TRIM`] neighbours furthest from the first plane, so
/// other outliers next to `p` cannot tilt it. Offsets 0 when the neighbours
/// are (nearly) collinear and define no plane.
fn plane_offset(p: &Vector3, others: &[Vector3]) -> PlaneFit {
    let none = |untrimmed| PlaneFit {
        offset: 0.0,
        sigma: 0.0,
        untrimmed,
        plane: None,
    };
    let Some((c, n, untrimmed)) = plane(others) else {
        return none(0.0);
    };
    let mut by_residual: Vec<(Real, usize)> = others
        .iter()
        .enumerate()
        .map(|(i, q)| ((q - c).dot(&n).abs(), i))
        .collect();
    by_residual.sort_by(|a, b| a.0.total_cmp(&b.0));
    let rest: Vec<Vector3> = by_residual[..others.len().saturating_sub(TRIM)]
        .iter()
        .map(|&(_, i)| others[i])
        .collect();
    match plane(&rest) {
        Some((c, n, sigma)) => PlaneFit {
            offset: (p - c).dot(&n).abs(),
            sigma,
            untrimmed,
            plane: Some((c, n)),
        },
        None => none(untrimmed),
    }
}

/// Whether `p`, off the trimmed plane of its neighbours (`limit(σ)` of
/// [`one_pass`]), is a sample of a sheet it shares with the neighbours the
/// trim left out rather than an outlier: at least [`TRIM`] neighbours are
/// off the plane too, all on `p`'s side and between half and twice its
/// offset. That is how a row of samples looks across a crease or a bend
/// sampled more coarsely than its curvature (noise-free CAD vertices: 531
/// of the 555 points the plane test flags on `fandisk`'s), whereas an
/// outlier beside a surface has no such companions (none of the 1,443 true
/// outliers the plane test flags on the corpus scans with 5 % outliers).
/// Piecewise-smooth surfaces meeting at creases: Hoppe et al. 1994.
fn shares_a_sheet(p: &Vector3, others: &[Vector3], limit: impl Fn(Real) -> Real) -> bool {
    let fit = plane_offset(p, others);
    let Some((c, n)) = fit.plane else {
        return false;
    };
    let cut = limit(fit.sigma);
    let offset = (p - c).dot(&n);
    let off: Vec<Real> = others
        .iter()
        .map(|q| (q - c).dot(&n))
        .filter(|r| r.abs() > cut)
        .collect();
    off.len() >= TRIM
        && off
            .iter()
            .all(|&r| r * offset > 0.0 && (0.5..=2.0).contains(&(r / offset)))
}

/// Centroid, unit normal (smallest principal axis) and RMS residual of the
/// least-squares plane of `pts`; `None` for fewer than 3 points or (nearly)
/// collinear ones.
pub(crate) fn plane(pts: &[Vector3]) -> Option<(Vector3, Vector3, Real)> {
    if pts.len() < 3 {
        return None;
    }
    let c = pts.iter().sum::<Vector3>() / pts.len() as Real;
    let mut cov = nalgebra::Matrix3::<Real>::zeros();
    for q in pts {
        let d = q - c;
        cov += d * d.transpose();
    }
    cov /= pts.len() as Real;
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let [small, middle, large] = order.map(|k| eig.eigenvalues[k]);
    if middle <= 0.01 * large {
        return None;
    }
    let n = eig.eigenvectors.column(order[0]).into_owned();
    Some((c, n, small.max(0.0).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Noise-free vertices of an eight-sided prism (radius 0.15, 30 rows
    /// 0.1 apart): every point lies on a sharp edge, and each row of its
    /// neighbours is off the plane of the other two. (Before the
    /// [`shares_a_sheet`] rule, 224 of these 240 points were "outliers".)
    fn prism() -> Vec<Point3> {
        let mut pts = Vec::new();
        for i in 0..8 {
            let a = std::f64::consts::TAU * i as Real / 8.0;
            for j in 0..30 {
                pts.push(Point3::new(0.15 * a.cos(), 0.15 * a.sin(), 0.1 * j as Real));
            }
        }
        pts
    }

    #[test]
    fn sharp_edges_are_kept_and_an_outlier_beside_them_is_not() {
        let mut pts = prism();
        let s = screen(&pts);
        let lost = s.keep.iter().filter(|&&k| !k).count();
        assert_eq!(lost, 0, "{lost} of {} edge points dropped", pts.len());
        // Off the middle of a side face, 0.06 outwards, halfway between rows.
        let mid = Point3::new(
            0.5 * (0.15 + 0.15 * std::f64::consts::FRAC_1_SQRT_2),
            0.5 * 0.15 * std::f64::consts::FRAC_1_SQRT_2,
            1.45,
        );
        let out = mid + Vector3::new(0.924, 0.383, 0.0) * 0.06;
        pts.push(out);
        let s = screen(&pts);
        assert!(!s.keep[pts.len() - 1], "the outlier was kept");
        assert_eq!(s.keep.iter().filter(|&&k| !k).count(), 1);
    }
}

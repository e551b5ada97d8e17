//! `compare`: distances from a surface (or a point cloud) `A` to a reference
//! surface `B` — one-sided statistics both ways, symmetric Chamfer and
//! Hausdorff distances, normal consistency — in absolute units and in
//! percent of `B`'s bounding-box diagonal.
//!
//! Definitions (the report states them too):
//!
//! - **Query points of a surface**: `samples` area-weighted points on its
//!   triangles ([`Surface::samples`], Monte-Carlo surface integration as in
//!   Cignoni, Rocchini, Scopigno, "Metro: measuring error on simplified
//!   surfaces", *CGF* 17(2), 1998), so the mean and RMS estimate
//!   `(1/|A|) ∫_A d(x, B) dA` and its quadratic analogue, not a per-vertex
//!   average that over-weights densely meshed regions. The surface's
//!   vertices are queried too, for the maximum only (they are where the
//!   largest deviations of piecewise-linear and fitted surfaces usually
//!   sit). With `samples = 0` the vertices alone are the query points.
//!   A point cloud's query points are its points.
//! - **One-sided `A → B`**: `d(x, B) = min_{y ∈ B} |x − y|`, exact
//!   point-to-surface distance, over `A`'s query points: [`DistanceStats`];
//!   `max` is over the samples and the vertices (the one-sided Hausdorff
//!   distance, a lower bound of the continuous one).
//! - **Chamfer** (symmetric): the mean of the two one-sided means,
//!   `½ (mean_{A→B} + mean_{B→A})`.
//! - **Hausdorff** (symmetric): `max(max_{A→B}, max_{B→A})`.
//! - **Normal consistency**: the mean over query points of `|n_x · n_y|`,
//!   `n_x` the unit normal at the query point (face normal of its triangle,
//!   limit normal, or the cloud's own normal), `n_y` the one at its closest
//!   point; 1 for parallel surfaces whatever their orientation. The
//!   symmetric figure is the mean of the two directions.
//! - **Percent**: every figure `× 100 / diag(B)`, `diag(B)` the bounding-box
//!   diagonal of `B`'s vertices ([`Surface::diagonal`]).
//! - **A point cloud `A`**: only `A → B` exists; `chamfer` and `hausdorff`
//!   are then the one-sided mean and max, and `symmetric` is false.

use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::stats::DistanceStats;
use super::surface::Surface;

/// Options of [`compare`].
#[derive(Clone, Debug)]
pub struct CompareParams {
    /// Area-weighted sample points per surface (default 100,000); 0 queries
    /// the vertices only.
    pub samples: usize,
    /// Seed of the sample positions (default 0); `B`'s samples use `seed + 1`.
    pub seed: u64,
}

impl Default for CompareParams {
    fn default() -> Self {
        CompareParams {
            samples: 100_000,
            seed: 0,
        }
    }
}

/// Distances from one side's query points to the other side.
#[derive(Clone, Debug, Serialize)]
pub struct OneSided {
    /// Statistics over the query points (samples, or cloud points).
    pub stats: DistanceStats,
    /// The same in percent of the reference diagonal.
    pub stats_pct: DistanceStats,
    /// Vertices queried in addition, for the maximum (0 when none).
    pub vertices: usize,
    /// The largest vertex distance, when vertices were queried in addition.
    pub vertex_max: Option<Real>,
    /// One-sided Hausdorff distance: the largest of all distances.
    pub max: Real,
    /// `max` in percent of the reference diagonal.
    pub max_pct: Real,
    /// Mean `|n_x · n_y|` (None when no query point has a normal).
    pub normal_consistency: Option<Real>,
    /// Seconds spent in the closest-point queries.
    pub query_s: Real,
    /// The query points, in order (not serialised).
    #[serde(skip)]
    pub queries: Vec<Point3>,
    /// The distance of each query point (not serialised).
    #[serde(skip)]
    pub distances: Vec<Real>,
}

/// The comparison of `A` with the reference `B` (see the module docs for
/// every definition).
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Bounding-box diagonal of `B`, the unit of the percentages.
    pub diagonal: Real,
    /// True when both directions were measured (`A` is a surface).
    pub symmetric: bool,
    /// `A → B`.
    pub a_to_b: OneSided,
    /// `B → A` (None for a point cloud `A`).
    pub b_to_a: Option<OneSided>,
    /// Chamfer distance `½ (mean_{A→B} + mean_{B→A})` (one-sided mean for a cloud).
    pub chamfer: Real,
    /// `chamfer` in percent of the diagonal.
    pub chamfer_pct: Real,
    /// Hausdorff distance `max(max_{A→B}, max_{B→A})` (one-sided max for a cloud).
    pub hausdorff: Real,
    /// `hausdorff` in percent of the diagonal.
    pub hausdorff_pct: Real,
    /// Mean of the directions' normal consistencies that exist.
    pub normal_consistency: Option<Real>,
}

/// Compares the surface `a` with the reference surface `b`, both ways.
///
/// ```
/// use subdyn::math::Vector3;
/// use subdyn::metrics::{CompareParams, Surface, compare};
/// let cube = subdyn::examples::cube();
/// let mut moved = cube.clone();
/// moved.positions.iter_mut().for_each(|p| *p += Vector3::new(0.0, 0.0, 0.01));
/// let params = CompareParams { samples: 2000, ..CompareParams::default() };
/// let c = compare(&Surface::mesh(&moved)?, &Surface::mesh(&cube)?, &params)?;
/// assert!((c.hausdorff - 0.01).abs() < 1e-12);
/// assert!(c.chamfer > 0.0 && c.chamfer < 0.01);
/// assert!((c.hausdorff_pct - 100.0 * 0.01 / 3f64.sqrt()).abs() < 1e-9);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn compare(a: &Surface, b: &Surface, params: &CompareParams) -> Result<Comparison> {
    let diagonal = reference_diagonal(b)?;
    let a_to_b = surface_to(a, b, params.samples, params.seed, diagonal)?;
    let b_to_a = surface_to(b, a, params.samples, params.seed.wrapping_add(1), diagonal)?;
    let chamfer = 0.5 * (a_to_b.stats.mean + b_to_a.stats.mean);
    let hausdorff = a_to_b.max.max(b_to_a.max);
    let normals: Vec<Real> = [a_to_b.normal_consistency, b_to_a.normal_consistency]
        .into_iter()
        .flatten()
        .collect();
    let normal_consistency =
        (!normals.is_empty()).then(|| normals.iter().sum::<Real>() / normals.len() as Real);
    Ok(Comparison {
        diagonal,
        symmetric: true,
        a_to_b,
        b_to_a: Some(b_to_a),
        chamfer,
        chamfer_pct: 100.0 * chamfer / diagonal,
        hausdorff,
        hausdorff_pct: 100.0 * hausdorff / diagonal,
        normal_consistency,
    })
}

/// Compares the points `points` (with their normals, if any) with the
/// reference surface `b`: the one-sided figures only.
pub fn compare_points(
    points: &[Point3],
    normals: Option<&[Vector3]>,
    b: &Surface,
) -> Result<Comparison> {
    let diagonal = reference_diagonal(b)?;
    if points.is_empty() {
        return Err(Error::input("no points to compare"));
    }
    if let Some(n) = normals
        && n.len() != points.len()
    {
        return Err(Error::size_mismatch(format!(
            "{} normals for {} points",
            n.len(),
            points.len()
        )));
    }
    let a_to_b = one_sided(points.to_vec(), normals, &[], b, diagonal)?;
    Ok(Comparison {
        diagonal,
        symmetric: false,
        chamfer: a_to_b.stats.mean,
        chamfer_pct: 100.0 * a_to_b.stats.mean / diagonal,
        hausdorff: a_to_b.max,
        hausdorff_pct: 100.0 * a_to_b.max / diagonal,
        normal_consistency: a_to_b.normal_consistency,
        a_to_b,
        b_to_a: None,
    })
}

fn reference_diagonal(b: &Surface) -> Result<Real> {
    let d = b.diagonal();
    if d > 0.0 && d.is_finite() {
        Ok(d)
    } else {
        Err(Error::input(format!(
            "the reference surface has bounding-box diagonal {d}; percentages need a positive one"
        )))
    }
}

/// `from → to` with `samples` samples on `from` (or its vertices alone).
fn surface_to(
    from: &Surface,
    to: &Surface,
    samples: usize,
    seed: u64,
    diagonal: Real,
) -> Result<OneSided> {
    if samples == 0 {
        return one_sided(from.vertices().to_vec(), None, &[], to, diagonal);
    }
    let (points, normals): (Vec<Point3>, Vec<Vector3>) =
        from.samples(samples, seed)?.into_iter().unzip();
    one_sided(points, Some(&normals), from.vertices(), to, diagonal)
}

/// Distances of `queries` (normals `normals`) and, for the max only, of
/// `extra` to `to`.
fn one_sided(
    queries: Vec<Point3>,
    normals: Option<&[Vector3]>,
    extra: &[Point3],
    to: &Surface,
    diagonal: Real,
) -> Result<OneSided> {
    let start = Instant::now();
    let mut all = queries;
    let n = all.len();
    all.extend_from_slice(extra);
    let found = to.closest_points(&all)?;
    let query_s = start.elapsed().as_secs_f64();
    all.truncate(n);
    let distances: Vec<Real> = found[..n].iter().map(|f| f.distance).collect();
    let stats = DistanceStats::new(&distances)?;
    let vertex_max =
        (!extra.is_empty()).then(|| found[n..].iter().map(|f| f.distance).fold(0.0, Real::max));
    let max = stats.max.max(vertex_max.unwrap_or(0.0));
    let normal_consistency = normals.and_then(|normals| {
        let dots: Vec<Real> = normals
            .iter()
            .zip(&found[..n])
            .filter_map(|(nx, f)| {
                let nx = nx.try_normalize(0.0)?;
                let ny = f.normal.try_normalize(0.0)?;
                Some(nx.dot(&ny).abs().min(1.0))
            })
            .collect();
        (!dots.is_empty()).then(|| dots.iter().sum::<Real>() / dots.len() as Real)
    });
    Ok(OneSided {
        stats_pct: stats.scaled(100.0 / diagonal),
        stats,
        vertices: extra.len(),
        vertex_max,
        max,
        max_pct: 100.0 * max / diagonal,
        normal_consistency,
        query_s,
        queries: all,
        distances,
    })
}

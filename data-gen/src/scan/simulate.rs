//! `simulated_scan`: cast every pixel's ray at the ground truth, add range
//! noise, drop points, add outliers.

use subdyn::math::{Point3, Real, Vector3};
use subdyn::metrics::TriangleBvh;

use super::camera::Camera;
use crate::rng::Rng;

/// What normals the scan carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalKind {
    /// None.
    None,
    /// The hit triangle's normal (exact for the reference mesh).
    Face,
    /// Area-weighted vertex normals interpolated with the hit's barycentric coordinates.
    Smooth,
}

/// Scanner settings that do not depend on the pose.
#[derive(Clone, Debug)]
pub struct SensorModel {
    /// Standard deviation of the range noise (model units).
    pub sigma: Real,
    /// Probability that a hit is lost.
    pub dropout: Real,
    /// Fraction of the output points that are outliers.
    pub outliers: Real,
    /// Normals to write.
    pub normals: NormalKind,
    /// Seed of all random streams.
    pub seed: u64,
    /// Outliers are uniform in this box.
    pub outlier_box: (Point3, Point3),
}

/// Per-view counts.
#[derive(Clone, Debug, Default)]
pub struct ViewCounts {
    /// Rays cast.
    pub rays: usize,
    /// Rays that hit the mesh.
    pub hits: usize,
    /// Hits lost to dropout.
    pub dropped: usize,
    /// Surface points kept.
    pub points: usize,
    /// Outliers assigned to this view.
    pub outliers: usize,
}

/// A simulated scan: surface points view by view (pixel order), then the outliers.
#[derive(Clone, Debug, Default)]
pub struct Scan {
    /// Positions.
    pub positions: Vec<Point3>,
    /// Normals (empty for [`NormalKind::None`]).
    pub normals: Vec<Vector3>,
    /// View index of every point.
    pub views: Vec<u32>,
    /// Counts per view.
    pub counts: Vec<ViewCounts>,
    /// Index of the first outlier (= number of surface points).
    pub first_outlier: usize,
}

/// Stream ids: pixels use `(view, pixel)`; outliers use `(OUTLIER_STREAM, k)`.
const OUTLIER_STREAM: u64 = u64::MAX;

/// One hit: position, normal.
type Sample = (Point3, Vector3);

/// Simulates the scan: for each view and pixel, the first hit at `t` along
/// the unit ray `d` becomes `o + (t + σ g) d` (`g ~ N(0, 1)`) unless dropped
/// (probability `dropout`); its normal faces the sensor (`n · d < 0`). Then
/// `round(outliers / (1 − outliers) · surface points)` outliers, uniform in
/// the outlier box, each given to a random view with a random unit normal
/// facing that view's eye. Every pixel and every outlier has its own random
/// stream, so the result does not depend on the number of threads.
pub fn simulated_scan(bvh: &TriangleBvh, cameras: &[Camera], model: &SensorModel) -> Scan {
    let vertex_normals = match model.normals {
        NormalKind::Smooth => Some(area_weighted_normals(bvh)),
        _ => None,
    };
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(16);
    let mut scan = Scan::default();
    for (v, camera) in cameras.iter().enumerate() {
        let (w, h) = camera.size;
        let pixels = w * h;
        let chunk = pixels.div_ceil(threads).max(1);
        let parts: Vec<(Vec<Sample>, usize, usize)> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..pixels)
                .step_by(chunk)
                .map(|start| {
                    let end = (start + chunk).min(pixels);
                    let vn = vertex_normals.as_deref();
                    s.spawn(move || scan_pixels(bvh, camera, model, vn, v as u64, start..end))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_default())
                .collect()
        });
        let mut counts = ViewCounts {
            rays: pixels,
            ..ViewCounts::default()
        };
        for (samples, hits, dropped) in parts {
            counts.hits += hits;
            counts.dropped += dropped;
            counts.points += samples.len();
            for (p, n) in samples {
                scan.positions.push(p);
                if model.normals != NormalKind::None {
                    scan.normals.push(n);
                }
                scan.views.push(v as u32);
            }
        }
        scan.counts.push(counts);
    }
    scan.first_outlier = scan.positions.len();

    let p = model.outliers;
    let n_out = if p > 0.0 {
        (p / (1.0 - p) * scan.first_outlier as Real).round() as usize
    } else {
        0
    };
    let (lo, hi) = model.outlier_box;
    for k in 0..n_out {
        let mut rng = Rng::for_item(model.seed, OUTLIER_STREAM, k as u64);
        let q = Point3::new(
            rng.uniform_in(lo.x, hi.x),
            rng.uniform_in(lo.y, hi.y),
            rng.uniform_in(lo.z, hi.z),
        );
        let v = rng.below(cameras.len() as u64) as usize;
        let mut n = Vector3::from(rng.unit_vector());
        if n.dot(&(cameras[v].eye - q)) < 0.0 {
            n = -n;
        }
        scan.positions.push(q);
        if model.normals != NormalKind::None {
            scan.normals.push(n);
        }
        scan.views.push(v as u32);
        scan.counts[v].outliers += 1;
    }
    scan
}

/// Casts the rays of pixels `range` of one view; returns the kept samples,
/// the number of hits and the number dropped.
fn scan_pixels(
    bvh: &TriangleBvh,
    camera: &Camera,
    model: &SensorModel,
    vertex_normals: Option<&[Vector3]>,
    view: u64,
    range: std::ops::Range<usize>,
) -> (Vec<Sample>, usize, usize) {
    let w = camera.size.0;
    let mut samples = Vec::new();
    let (mut hits, mut dropped) = (0, 0);
    for pixel in range {
        let (origin, dir) = camera.ray(pixel % w, pixel / w);
        let Some(hit) = bvh.ray_cast(origin, dir, Real::INFINITY) else {
            continue;
        };
        hits += 1;
        let mut rng = Rng::for_item(model.seed, view, pixel as u64);
        let lost = rng.chance(model.dropout);
        let g = rng.gaussian();
        if lost {
            dropped += 1;
            continue;
        }
        let point = origin + dir * (hit.t + model.sigma * g);
        let mut normal = match vertex_normals {
            Some(vn) => {
                let tri = bvh.triangles()[hit.triangle];
                let n = (0..3).fold(Vector3::zeros(), |s, k| {
                    s + vn[tri[k] as usize] * hit.bary[k]
                });
                n.try_normalize(1e-300)
                    .unwrap_or_else(|| bvh.triangle_normal(hit.triangle))
            }
            None => bvh.triangle_normal(hit.triangle),
        };
        if normal.dot(&dir) > 0.0 {
            normal = -normal;
        }
        samples.push((point, normal));
    }
    (samples, hits, dropped)
}

/// Per-vertex normals: the sum of the incident triangles' area-weighted normals, normalised.
fn area_weighted_normals(bvh: &TriangleBvh) -> Vec<Vector3> {
    let p = bvh.positions();
    let mut n = vec![Vector3::zeros(); p.len()];
    for tri in bvh.triangles() {
        let [a, b, c] = tri.map(|v| p[v as usize]);
        let area_normal = (b - a).cross(&(c - a));
        for &v in tri {
            n[v as usize] += area_normal;
        }
    }
    n.into_iter()
        .map(|v| v.try_normalize(1e-300).unwrap_or_else(Vector3::zeros))
        .collect()
}

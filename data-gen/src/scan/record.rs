//! `scan_record`: the scan sidecar's JSON.

use std::path::Path;

use serde_json::{Value, json};
use subdyn::math::{Point3, Real};

use super::args::ScanJob;
use super::camera::{Camera, Pose};
use super::ply::properties;
use super::simulate::{NormalKind, Scan, SensorModel};
use crate::sidecar::{GENERATOR, box_json, path_from_sidecar, xyz};

/// How the sensors were set up for a scan.
pub struct Setup<'a> {
    /// One pose per view.
    pub poses: &'a [Pose],
    /// The cameras built from them.
    pub cameras: &'a [Camera],
    /// Noise, dropout, outliers, normals, seed.
    pub model: &'a SensorModel,
    /// Bounding-box diagonal of the ground truth.
    pub diag: Real,
    /// Eye distance in diagonals (Fibonacci views).
    pub distance: Real,
}

/// The sidecar of `scan`: files, ground truth, every parameter, counts, outliers, per-view poses.
pub fn scan_record(
    job: &ScanJob,
    truth: Value,
    setup: &Setup,
    scan: &Scan,
    sidecar: &Path,
) -> Value {
    let (cameras, poses, model, diag, distance) = (
        setup.cameras,
        setup.poses,
        setup.model,
        setup.diag,
        setup.distance,
    );
    let surface: usize = scan.first_outlier;
    let outliers = scan.positions.len() - surface;
    let views: Vec<Value> = cameras
        .iter()
        .zip(poses)
        .zip(&scan.counts)
        .enumerate()
        .map(|(i, ((cam, pose), c))| {
            json!({
                "view": i,
                "eye": pose.eye,
                "target": pose.target,
                "up": xyz(&Point3::from(cam.up)),
                "forward": xyz(&Point3::from(cam.forward)),
                "rays": c.rays,
                "hits": c.hits,
                "dropped": c.dropped,
                "points": c.points,
                "outliers": c.outliers,
            })
        })
        .collect();
    let normals = match job.normals {
        NormalKind::None => "none",
        NormalKind::Face => {
            "ground truth: the normal of the reference-mesh triangle hit by the ray, flipped to face the sensor (n · ray direction < 0); outliers get random unit normals facing their view's eye"
        }
        NormalKind::Smooth => {
            "ground truth, smoothed: area-weighted vertex normals of the reference mesh interpolated at the hit, flipped to face the sensor (n · ray direction < 0); outliers get random unit normals facing their view's eye"
        }
    };
    json!({
        "generator": GENERATOR,
        "kind": "range_scan",
        "points": path_from_sidecar(&job.output, sidecar),
        "ground_truth_mesh": path_from_sidecar(&job.truth, sidecar),
        "ground_truth": truth,
        "parameters": {
            "views": cameras.len(),
            "poses_file": job.poses.as_ref().map(|p| p.to_string_lossy().into_owned()),
            "view_placement": if job.poses.is_some() { "poses file" } else { "Fibonacci sphere around the bounding-box centre, looking at it" },
            "projection": if job.perspective { "perspective" } else { "orthographic" },
            "fov_deg": if job.perspective { json!(job.fov) } else { Value::Null },
            "orthographic_window_height": if job.perspective { Value::Null } else { json!(1.05 * diag) },
            "distance_diagonals": if job.poses.is_some() { Value::Null } else { json!(distance) },
            "resolution": [job.resolution.0, job.resolution.1],
            "noise": job.noise,
            "noise_sigma": model.sigma,
            "dropout": job.dropout,
            "outliers": job.outliers,
            "seed": job.seed,
            "precision": job.precision.ply_name(),
        },
        "noise_model": "a hit at distance t along the unit ray direction d from origin o is written as o + (t + sigma g) d, g ~ N(0, 1), sigma = noise × bounding-box diagonal; each hit is lost with probability `dropout`",
        "normals": normals,
        "ply": {
            "format": "binary_little_endian 1.0",
            "vertex_properties": properties(job.precision, job.normals != NormalKind::None)
                .iter().map(|(t, n)| format!("{t} {n}")).collect::<Vec<_>>(),
            "order": "surface points view by view in pixel order (row by row from the top left), then the outliers",
        },
        "counts": {
            "rays": scan.counts.iter().map(|c| c.rays).sum::<usize>(),
            "hits": scan.counts.iter().map(|c| c.hits).sum::<usize>(),
            "dropped": scan.counts.iter().map(|c| c.dropped).sum::<usize>(),
            "surface_points": surface,
            "outliers": outliers,
            "total": scan.positions.len(),
        },
        "outliers": {
            "count": outliers,
            "first_index": surface,
            "box": box_json(&[model.outlier_box.0, model.outlier_box.1]),
            "rule": "round(outliers / (1 - outliers) × surface points), uniform in the box, each assigned to a random view",
        },
        "views": views,
    })
}

//! `data-gen scan`: builds the ground truth, places the sensors, simulates
//! the scan and writes the PLY, the ground-truth mesh and the sidecar.

use anyhow::{Context, Result, bail};
use serde_json::Value;
use subdyn::math::{Point3, Real, Vector3};
use subdyn::metrics::TriangleBvh;

use super::args::{ScanArgs, ScanJob};
use super::camera::{Camera, Pose, Projection, fibonacci_poses, read_poses};
use super::ply::write_scan_ply;
use super::record::{Setup, scan_record};
use super::simulate::{SensorModel, simulated_scan};
use crate::sidecar::{create_parent, path_from_sidecar, sidecar_path, write_json};
use crate::truth::ground_truth;

/// Runs `data-gen scan`.
pub fn run(args: &ScanArgs) -> Result<()> {
    let job = ScanJob::from_args(args)?;
    let record = run_scan(&job)?;
    let c = &record["counts"];
    println!(
        "{}: {} points ({} surface, {} outliers) from {} views; ground truth {}; sidecar {}",
        job.output.display(),
        c["total"],
        c["surface_points"],
        c["outliers"],
        record["parameters"]["views"],
        job.truth.display(),
        sidecar_path(&job.output).display()
    );
    Ok(())
}

/// Runs a scan job: writes the PLY, the ground-truth mesh and the sidecar;
/// returns the sidecar's contents.
pub fn run_scan(job: &ScanJob) -> Result<Value> {
    job.check()?;
    let truth = ground_truth(&job.source)?;
    let bvh = TriangleBvh::from_mesh(&truth.mesh).context("building the ray-casting hierarchy")?;
    let (lo, hi) =
        subdyn::math::bounding_box(&truth.mesh.positions).context("the mesh has no vertices")?;
    let diag = (hi - lo).norm();
    if diag <= 0.0 {
        bail!("the ground-truth mesh has a zero-size bounding box");
    }
    let centre = Point3::from((lo.coords + hi.coords) * 0.5);

    let projection = if job.perspective {
        Projection::Perspective { fov_deg: job.fov }
    } else {
        Projection::Orthographic {
            height: 1.05 * diag,
        }
    };
    // Perspective: the bounding sphere (radius diag/2) just fits the smaller
    // field of view, with 5 % to spare.
    let half_fov = 0.5 * job.fov.to_radians();
    let aspect = job.resolution.0 as Real / job.resolution.1 as Real;
    let half_min = half_fov.tan().min(half_fov.tan() * aspect).atan();
    let distance = job.distance.unwrap_or(if job.perspective {
        1.05 * 0.5 / half_min.sin()
    } else {
        1.0
    });
    let poses: Vec<Pose> = match &job.poses {
        Some(path) => read_poses(path, &centre)?,
        None => fibonacci_poses(job.views, &centre, distance * diag),
    };
    let cameras: Vec<Camera> = poses
        .iter()
        .map(|p| Camera::new(p, job.resolution, projection))
        .collect();

    let margin = Vector3::repeat(0.1 * diag);
    let model = SensorModel {
        sigma: job.noise * diag,
        dropout: job.dropout,
        outliers: job.outliers,
        normals: job.normals,
        seed: job.seed,
        outlier_box: (lo - margin, hi + margin),
    };
    let scan = simulated_scan(&bvh, &cameras, &model);
    if scan.positions.is_empty() {
        bail!("no ray hit the mesh; check --poses, --distance and --fov");
    }

    let sidecar = sidecar_path(&job.output);
    let comment = format!(
        "data-gen range scan; see {}",
        path_from_sidecar(&sidecar, &job.output)
    );
    create_parent(&job.output)?;
    create_parent(&job.truth)?;
    subdyn::io::write_mesh(&job.truth, &truth.mesh, None)?;
    write_scan_ply(&job.output, &scan, job.precision, &comment)?;

    let setup = Setup {
        poses: &poses,
        cameras: &cameras,
        model: &model,
        diag,
        distance,
    };
    let mut record = scan_record(job, truth.info, &setup, &scan, &sidecar);
    if let (Some(out), Value::Object(extra)) = (record.as_object_mut(), &job.extra) {
        for (k, v) in extra {
            out.insert(k.clone(), v.clone());
        }
    }
    write_json(&sidecar, &record)?;
    Ok(record)
}

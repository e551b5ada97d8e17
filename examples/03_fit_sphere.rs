//! Fit a dynamic Catmull-Clark surface to a scan with the library's defaults
//! (Qin, Mandal, Vemuri 1998, §6): `subdyn::fit::fit_from_start` builds the
//! initial control mesh from the points (`InitParams::default()`, what
//! `subdyn fit --init auto` does) and refines it level by level until the
//! 95th percentile of the data-to-surface distances is within 0.1 % of the
//! scan's diagonal (`FitParams::default()`).
//!
//! Input: a scan (`.ply`, `.xyz`, `.obj`, `.off`; only the points are used)
//! as the first argument; without it, a noisy scan of the unit sphere is made
//! here (10,000 points, range noise σ = 0.1 % of the diagonal). Outputs in
//! `target/examples-out/`: `fit_control.obj` (the fitted control mesh),
//! `fit_limit.ply` (its limit surface, the file to use downstream) and
//! `fit.png` (the limit surface inside the control mesh). Prints the points,
//! control points, levels, the 95th-percentile error and the time.
//! Run with `cargo run --release --example 03_fit_sphere [SCAN]`.

mod common;

use std::f64::consts::TAU;
use std::process::ExitCode;

use subdyn::fit::init::InitParams;
use subdyn::fit::{FitParams, FitStart, fit_from_start};
use subdyn::io::{read_points, write_mesh};
use subdyn::limit::limit_surface_mesh;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PointCloud;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};
use subdyn::subdivision::RefineOptions;

/// `n` points on the unit sphere, moved along the radius by Gaussian noise
/// of σ = 0.1 % of the bounding-box diagonal (2√3); a fixed seed.
fn sphere_scan(n: usize) -> subdyn::Result<PointCloud> {
    let mut seed = 1u64;
    let mut uniform = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let sigma = 0.001 * 2.0 * 3f64.sqrt();
    let points = (0..n)
        .map(|_| {
            let z = 2.0 * uniform() - 1.0;
            let t = TAU * uniform();
            let r = (1.0 - z * z).sqrt();
            // Box-Muller.
            let g = (-2.0 * uniform().max(1e-300).ln()).sqrt() * (TAU * uniform()).cos();
            Point3::from(Vector3::new(r * t.cos(), r * t.sin(), z) * (1.0 + sigma * g))
        })
        .collect();
    PointCloud::new(points, None)
}

fn run() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let (cloud, name) = match std::env::args().nth(1) {
        Some(path) => (read_points(&path)?, path),
        None => (sphere_scan(10_000)?, "a noisy unit sphere".to_string()),
    };
    let start = FitStart::Method(InitParams::default());
    let fitted = fit_from_start(&cloud, &start, &FitParams::default(), &mut |_, _, _| {})?;
    let control = &fitted.result.control;
    let report = &fitted.result.report;
    let last = report.levels.last();
    println!(
        "fitted {name}: {} points → {} control points (levels: {}), error p95 {:.3} % of the diagonal (all points), {:.2} s",
        report.points,
        control.num_vertices(),
        report.levels.len(),
        last.map_or(f64::NAN, |l| l.error.p95_pct),
        report.seconds
    );
    println!("{}", report.stop_reason);

    let control_path = out.join("fit_control.obj");
    write_mesh(&control_path, control, None)?;
    let (surface, normals) = limit_surface_mesh(control, &RefineOptions::default(), 4, false)?;
    let limit_path = out.join("fit_limit.ply");
    write_mesh(&limit_path, &surface, Some(&normals))?;
    let scene = Scene {
        meshes: vec![
            MeshLayer::new(&surface).with_normals(&normals),
            MeshLayer::wireframe(control, [200, 40, 40]),
        ],
        ..Scene::default()
    };
    let options = RenderOptions {
        width: 640,
        height: 480,
        azimuth: 30.0,
        elevation: 20.0,
        supersample: 2,
        title: Some("fit: limit surface, control mesh in red".into()),
        ..RenderOptions::default()
    };
    let picture_path = out.join("fit.png");
    write_png(&picture_path, &render(&scene, &options)?)?;
    for path in [&control_path, &limit_path, &picture_path] {
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("03_fit_sphere: {e}");
            ExitCode::FAILURE
        }
    }
}

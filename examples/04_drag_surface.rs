//! Drag a point of a dynamic Catmull-Clark surface (Qin, Mandal, Vemuri
//! 1998, §5.2) with the paper's second-order dynamics, let go, and watch it
//! swing on by its momentum and settle (the thin plate has no rest shape to
//! return to); every step solved both by sparse Cholesky (one factor per
//! spring attachment) and by conjugate gradients, to compare.
//!
//! Inputs: a control mesh (`.obj`, `.ply`, `.off`), default the cube
//! refined four times (1,538 control points). Outputs in
//! `target/examples-out/`: `drag_surface.obj` (the control mesh at the end of the drag)
//! and `drag_surface.png` (rest, dragged, released). Prints per phase the
//! time per step of either solver, the factorisations, the largest
//! difference between the two solvers' control points and the energy.
//! Run with `cargo run --release --example 04_drag_surface [MESH]`.

mod common;

use std::time::Instant;

use subdyn::dynamics::{LinearSolver, MaterialParams, PcgParams, SurfaceDynamics, parameter_area};
use subdyn::forces::drag_spring;
use subdyn::io::{read_mesh, write_mesh};
use subdyn::limit::{ClosestPointEngine, ClosestPointParams, tessellate};
use subdyn::math::{Point3, Real, Vector3, bbox_diagonal};
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, Picture, RenderOptions, Scene, render, write_png};
use subdyn::subdivision::{RefineOptions, Refiner};

fn picture(mesh: &PolyMesh, positions: &[Point3], title: &str) -> subdyn::Result<Picture> {
    let refiner = Refiner::new(mesh, &RefineOptions::default())?;
    let (surface, _) = tessellate(&refiner, positions, 4)?;
    let scene = Scene {
        meshes: vec![MeshLayer::new(&surface)],
        ..Scene::default()
    };
    render(
        &scene,
        &RenderOptions {
            width: 320,
            height: 300,
            azimuth: 35.0,
            elevation: 25.0,
            supersample: 2,
            title: Some(title.into()),
            ..RenderOptions::default()
        },
    )
}

fn main() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let mesh = match std::env::args().nth(1) {
        Some(path) => read_mesh(std::path::Path::new(&path))?,
        None => {
            let mut mesh = subdyn::examples::cube();
            for _ in 0..4 {
                let h = Refiner::new(&mesh, &RefineOptions::default())?.refine_uniform(1)?;
                let p = h.stencil(0).apply(&mesh.positions)?;
                mesh = h.mesh(1, p);
            }
            mesh
        }
    };
    let n = mesh.num_vertices();
    let diameter = bbox_diagonal(&mesh.positions);
    let refiner = Refiner::new(&mesh, &RefineOptions::default())?;
    let engine =
        ClosestPointEngine::new(&refiner, &mesh.positions, &ClosestPointParams::default())?;
    // Material over the parameter area `A` (the number of faces), as the fit
    // scales it; a heavy, lightly damped surface so that it swings.
    let area = parameter_area(engine.table());
    let material = MaterialParams {
        mu: 2.0 / area,
        gamma: 0.5 / area,
        ..MaterialParams::thin_plate(0.05, 0.5, area)
    };
    let dt = 0.02;
    let pcg = LinearSolver::Pcg(PcgParams {
        tolerance: 1e-13,
        max_iterations: 0,
    });
    let mut solvers = Vec::new();
    for solver in [LinearSolver::Cholesky, pcg] {
        solvers.push(SurfaceDynamics::on_patches(
            engine.table(),
            mesh.positions.clone(),
            &[material],
            4,
            dt,
            solver,
        )?);
    }
    // Grab the surface where it is closest to the mesh's farthest point
    // along x and pull it outwards by a fifth of the diagonal over 60 steps.
    let far = mesh
        .positions
        .iter()
        .copied()
        .max_by(|a, b| a.x.total_cmp(&b.x))
        .expect("a mesh has vertices");
    let at = engine.closest_points(&[far])?[0];
    let pull = Vector3::new(0.2 * diameter, 0.0, 0.0);
    let zero = vec![Point3::origin(); n];
    let mut frames = vec![picture(&mesh, &mesh.positions, "rest")?];
    println!(
        "{n} control points; {} steps of {dt} s per phase; per step: Cholesky | CG",
        60
    );
    for phase in ["drag", "release"] {
        let mut seconds = [0.0; 2];
        let mut cg_iterations = 0;
        let mut energy = 0.0;
        for k in 1..=60 {
            let t = k as Real / 60.0;
            let spring = match phase {
                "drag" => Some(drag_spring(&engine, &at, at.point + t * pull, 50.0)?),
                _ => None,
            };
            let (s, f) = match &spring {
                Some(s) => (Some(&s.matrix), &s.rhs[..]),
                None => (None, &zero[..]),
            };
            for (i, d) in solvers.iter_mut().enumerate() {
                let start = Instant::now();
                let report = d.step(s, f)?;
                seconds[i] += start.elapsed().as_secs_f64();
                cg_iterations += report.cg_iterations;
                energy = report.energy;
            }
        }
        let gap = solvers[0]
            .positions()
            .iter()
            .zip(solvers[1].positions())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        println!(
            "{phase:>8}: {:.2} ms | {:.2} ms ({:.0} CG iterations per step); {} factorisations so far; solvers {:.1e} of the diagonal apart; energy {energy:.4e}",
            1e3 * seconds[0] / 60.0,
            1e3 * seconds[1] / 60.0,
            cg_iterations as Real / 60.0,
            solvers[0].factorizations(),
            gap / diameter
        );
        frames.push(picture(&mesh, solvers[0].positions(), phase)?);
        if phase == "drag" {
            let dragged = PolyMesh {
                positions: solvers[0].positions().to_vec(),
                ..mesh.clone()
            };
            write_mesh(out.join("drag_surface.obj"), &dragged, None)?;
        }
    }
    write_png(
        &out.join("drag_surface.png"),
        &Picture::side_by_side(&frames)?,
    )?;
    for name in ["drag_surface.obj", "drag_surface.png"] {
        println!("wrote {}", out.join(name).display());
    }
    Ok(())
}

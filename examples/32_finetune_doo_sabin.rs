//! Fine tuning of a Doo-Sabin surface (figure 16 of the fine-tuning paper in
//! spirit): the embedded unit cube read as a Doo-Sabin control mesh, the three
//! edges at its top vertex 7 = (1, 1, 1) get control value 1.3, three bottom
//! (y = 0) vertices 0, 1, 4 are fixed.
//!
//! Inputs: none (`subdyn::examples::cube`). Outputs (in the directory given as
//! the first argument, default `target/examples-out/`): `finetune_surface.png` — left the
//! converted non-uniform Catmull-Clark surface (ε = 0.05, depth 3) with its
//! control mesh, right the fine-tuned one coloured by how far the surface
//! moved (fraction of the cube's side); `finetune_surface.obj` — the
//! fine-tuned control mesh. Run: `cargo run --release --example 32_finetune_doo_sabin [DIR]`.

mod common;

use std::path::PathBuf;

use subdyn::finetune::{SurfaceFineTune, SurfaceFineTuneParams, SurfaceScheme};
use subdyn::math::Vector3;
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};
use subdyn::subdivision::NonUniformHierarchy;

fn refined(
    p: &SurfaceFineTune,
    control: &PolyMesh,
    shift: f64,
) -> subdyn::Result<(PolyMesh, PolyMesh)> {
    let h = NonUniformHierarchy::new(p.level.clone(), p.intervals.clone(), 3)?;
    let positions = h.stencil_to_level(3)?.apply(&control.positions)?;
    let l = &h.levels[3];
    let mv = |v: &Vec<subdyn::math::Point3>| -> Vec<subdyn::math::Point3> {
        v.iter().map(|q| q + screen_right() * shift).collect()
    };
    let surface = PolyMesh {
        positions: mv(&positions),
        face_offsets: l.face_offsets.clone(),
        face_vertices: l.face_verts.clone(),
    };
    let mut cage = control.clone();
    cage.positions = mv(&control.positions);
    Ok((surface, cage))
}

/// The screen's right vector for azimuth 20° about +Y.
fn screen_right() -> Vector3 {
    Vector3::new(20f64.to_radians().cos(), 0.0, -(20f64.to_radians().sin()))
}

fn main() -> subdyn::Result<()> {
    let dir = match std::env::args().nth(1) {
        Some(dir) => PathBuf::from(dir),
        None => common::output_dir()?,
    };
    let cube = subdyn::examples::cube();
    let values = [(7, 3, 1.3), (7, 5, 1.3), (7, 6, 1.3)];
    let p = SurfaceFineTune::new(
        &cube,
        SurfaceScheme::DooSabin,
        &values,
        &[0, 1, 4],
        &SurfaceFineTuneParams::default(),
    )?;
    let (out, report) = p.solve()?;
    println!(
        "energy {:.4e} -> {:.4e} in {} iterations ({}); largest move {:.4}; {:.1} ms",
        report.energies[0],
        report.energies.last().copied().unwrap_or(0.0),
        report.iterations,
        report.termination,
        report.max_displacement,
        1e3 * (report.seconds[0] + report.seconds[1])
    );
    let right = screen_right();
    let (before, cage0) = refined(&p, &p.mesh, 0.0)?;
    let (after, cage1) = refined(&p, &out, 1.8)?;
    let moved: Vec<f64> = after
        .positions
        .iter()
        .zip(&before.positions)
        .map(|(a, b)| (a - right * 1.8 - b).norm())
        .collect();
    let wire = [200, 40, 40];
    let scene = Scene {
        meshes: vec![
            MeshLayer::new(&before),
            MeshLayer::wireframe(&cage0, wire),
            MeshLayer::new(&after).with_scalars(&moved),
            MeshLayer::wireframe(&cage1, wire),
        ],
        ..Scene::default()
    };
    let options = RenderOptions {
        width: 900,
        height: 500,
        azimuth: 20.0,
        elevation: 25.0,
        supersample: 2,
        title: Some(
            "Doo-Sabin cube: converted (left); top edges at 1.3, vertices 0, 1, 4 fixed (right)"
                .into(),
        ),
        legend_label: Some("moved".into()),
        ..Default::default()
    };
    let picture = render(&scene, &options)?;
    write_png(&dir.join("finetune_surface.png"), &picture)?;
    subdyn::io::write_mesh(dir.join("finetune_surface.obj"), &out, None)?;
    for name in ["finetune_surface.png", "finetune_surface.obj"] {
        println!("wrote {}", dir.join(name).display());
    }
    Ok(())
}

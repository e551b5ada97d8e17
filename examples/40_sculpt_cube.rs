//! Sculpt the paper's 3×3×3-point cube as a dynamic subdivision solid
//! (McDonnell & Qin): fix its underside, drag a top corner with the rope
//! tool, let go, make the dragged shape plastic, then extrude the top face
//! and watch the new cell settle.
//!
//! Inputs: none. Outputs in `target/examples-out/`: `sculpt_cube.obj` (the
//! level-2 boundary surface at the end) and `sculpt_cube.png` (before,
//! dragged, after make plastic and extrusion). Prints the energies.
//! Run with `cargo run --release --example 40_sculpt_cube`.

mod common;

use subdyn::lattice::box_grid;
use subdyn::math::Point3;
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, Picture, RenderOptions, Scene, render, write_png};
use subdyn::solid::{Solid, SolidParams};

fn picture(mesh: &PolyMesh, title: &str) -> subdyn::Result<Picture> {
    let scene = Scene {
        meshes: vec![MeshLayer::new(mesh)],
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
    let cube = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [2, 2, 2])?;
    let mut solid = Solid::new(&cube, SolidParams::default())?;
    let bottom: Vec<usize> = (0..27)
        .filter(|&i| solid.control_points()[i].y < 0.01)
        .collect();
    solid.set_fixed(&bottom, true)?;
    let mut frames = vec![picture(&solid.boundary_mesh()?, "rest")?];

    let h = 0.01; // implicit steps; the explicit one needs h < ~0.007 here
    let corner = solid.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    let rope = solid.add_rope(corner, Point3::new(1.0, 1.0, 1.0), 150.0, 0.0)?;
    for k in 0..=60 {
        let t = f64::from(k) / 60.0;
        solid.set_rope_target(
            rope,
            Point3::new(1.0 + 0.5 * t, 1.0 + 0.6 * t, 1.0 + 0.5 * t),
        )?;
        solid.step_implicit(h)?;
    }
    println!(
        "dragged: spring energy {:.4}, rope energy {:.4}",
        solid.spring_energy(),
        solid.rope_energy()
    );
    frames.push(picture(&solid.boundary_mesh()?, "rope drag")?);

    solid.release_ropes();
    solid.make_plastic()?;
    solid.halt();
    let top = (0..solid.control_lattice().topology.num_faces())
        .find(|&f| {
            let lat = solid.control_lattice();
            lat.topology.is_boundary_face(f)
                && lat
                    .topology
                    .faces
                    .row(f)
                    .iter()
                    .all(|&v| lat.positions[v as usize].y > 0.99)
        })
        .ok_or_else(|| subdyn::Error::input("no top face"))?;
    solid.extrude(top)?;
    for _ in 0..100 {
        solid.step_implicit(h)?;
    }
    println!(
        "plastic + extruded: {} mass points, kinetic {:.2e}, spring {:.2e}",
        solid.mass_points().len(),
        solid.kinetic_energy(),
        solid.spring_energy()
    );
    let end = solid.boundary_mesh()?;
    frames.push(picture(&end, "plastic, extruded")?);
    subdyn::io::write_mesh(out.join("sculpt_cube.obj"), &end, None)?;
    write_png(
        &out.join("sculpt_cube.png"),
        &Picture::side_by_side(&frames)?,
    )?;
    for name in ["sculpt_cube.obj", "sculpt_cube.png"] {
        println!("wrote {}", out.join(name).display());
    }
    Ok(())
}

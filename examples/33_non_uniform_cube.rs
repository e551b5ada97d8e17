//! Non-uniform Catmull-Clark subdivision (Sederberg et al. 1998) of the unit
//! cube: the four edges parallel to the y axis get knot interval `d`, every
//! other edge 1. With `d = 1` this is uniform Catmull-Clark; small `d`
//! pulls the surface towards those edges.
//!
//! Inputs: none (`subdyn::examples::cube`). Outputs (in the directory given as
//! the first argument, default `target/examples-out/`): `non_uniform_cube.png`, the level-4
//! surfaces for `d = 1, 0.25, 0.02` from left to right.
//! Run: `cargo run --release --example 33_non_uniform_cube [DIR]`.

mod common;

use std::path::PathBuf;

use subdyn::math::Vector3;
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};
use subdyn::subdivision::NonUniformHierarchy;
use subdyn::topology::Level;

fn main() -> subdyn::Result<()> {
    let dir = match std::env::args().nth(1) {
        Some(dir) => PathBuf::from(dir),
        None => common::output_dir()?,
    };
    let cube = subdyn::examples::cube();
    let level = Level::from_mesh(&cube)?;
    // Screen right for the renderer's azimuth of 30° about +Y.
    let right = Vector3::new(30f64.to_radians().cos(), 0.0, -(30f64.to_radians().sin()));
    let mut surfaces = Vec::new();
    for (k, d) in [1.0, 0.25, 0.02].into_iter().enumerate() {
        let intervals: Vec<f64> = level
            .edge_verts
            .iter()
            .map(|&[a, b]| {
                let (pa, pb) = (cube.positions[a as usize], cube.positions[b as usize]);
                if (pa.x - pb.x).abs() + (pa.z - pb.z).abs() == 0.0 {
                    d
                } else {
                    1.0
                }
            })
            .collect();
        let h = NonUniformHierarchy::new(level.clone(), intervals, 4)?;
        let positions = h
            .stencil_to_level(4)?
            .apply(&cube.positions)?
            .into_iter()
            .map(|p| p + right * (1.6 * k as f64))
            .collect();
        surfaces.push(PolyMesh {
            positions,
            face_offsets: h.levels[4].face_offsets.clone(),
            face_vertices: h.levels[4].face_verts.clone(),
        });
        println!("d = {d}: {} faces", h.levels[4].num_faces());
    }
    let scene = Scene {
        meshes: surfaces.iter().map(MeshLayer::new).collect(),
        ..Scene::default()
    };
    let options = RenderOptions {
        width: 900,
        height: 380,
        supersample: 2,
        title: Some("non-uniform Catmull-Clark cube: y-edges at d = 1, 0.25, 0.02".into()),
        ..Default::default()
    };
    write_png(
        &dir.join("non_uniform_cube.png"),
        &render(&scene, &options)?,
    )?;
    println!("wrote {}", dir.join("non_uniform_cube.png").display());
    Ok(())
}

//! Twist, bend and taper a bar with a 4×1×1 box lattice refined three times
//! (MacCracken & Joy 1996). The bar is the boundary of a 32×8×8 grid.
//!
//! Inputs: none. Outputs in `target/examples-out/`: `bar_twist.obj`,
//! `bar_bend.obj`, `bar_taper.obj` and `bar_deformations.png` (the rest bar
//! and the three deformations side by side, lattices as wireframes).
//! Run with `cargo run --release --example 20_bar_twist_bend_taper`.

mod common;

use subdyn::ffd::{Ffd, FfdParams};
use subdyn::lattice::box_grid;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};

fn shifted(mesh: &PolyMesh, positions: &[Point3], dy: f64) -> PolyMesh {
    let mut m = mesh.clone();
    m.positions = positions
        .iter()
        .map(|p| p + Vector3::new(0.0, dy, 0.0))
        .collect();
    m
}

fn main() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let (len, w) = (4.0, 1.0);
    let bar = box_grid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(len, w, w),
        [32, 8, 8],
    )?
    .boundary_mesh()?;
    let lat = box_grid(
        Point3::new(-0.05, -0.05, -0.05),
        Point3::new(len + 0.05, w + 0.05, w + 0.05),
        [4, 1, 1],
    )?;
    let ffd = Ffd::new(
        &lat,
        &bar.positions,
        &FfdParams {
            levels: 3,
            ..Default::default()
        },
    )?;
    println!("{:?}", ffd.report);
    let c = Point3::new(0.0, 0.5 * w, 0.5 * w);
    let twist: Vec<Point3> = lat
        .positions
        .iter()
        .map(|p| {
            let a = std::f64::consts::PI * p.x / len; // half a turn along the bar
            let (y, z) = (p.y - c.y, p.z - c.z);
            Point3::new(
                p.x,
                c.y + a.cos() * y - a.sin() * z,
                c.z + a.sin() * y + a.cos() * z,
            )
        })
        .collect();
    let bend: Vec<Point3> = lat
        .positions
        .iter()
        .map(|p| {
            let r = 3.0; // bend about the line y = 0, z = r: a quarter circle
            let a = (std::f64::consts::FRAC_PI_2 / len) * p.x;
            let rho = r - p.z;
            Point3::new(rho * a.sin(), p.y, r - rho * a.cos())
        })
        .collect();
    let taper: Vec<Point3> = lat
        .positions
        .iter()
        .map(|p| {
            let s = 1.0 - 0.6 * p.x / len;
            Point3::new(p.x, c.y + s * (p.y - c.y), c.z + s * (p.z - c.z))
        })
        .collect();
    let mut meshes = vec![shifted(&bar, &bar.positions, 0.0)];
    let mut cages = vec![shifted(&lat.boundary_mesh()?, &lat.positions, 0.0)];
    for (k, (name, ctrl)) in [("twist", &twist), ("bend", &bend), ("taper", &taper)]
        .iter()
        .enumerate()
    {
        let moved = ffd.deform(ctrl)?;
        let mesh = shifted(&bar, &moved, 0.0);
        let path = out.join(format!("bar_{name}.obj"));
        subdyn::io::write_mesh(&path, &mesh, None)?;
        println!("wrote {}", path.display());
        let dy = 2.0 * (k + 1) as f64;
        meshes.push(shifted(&bar, &moved, dy));
        cages.push(shifted(&lat.boundary_mesh()?, ctrl, dy));
    }
    let mut scene = Scene::default();
    for m in &meshes {
        scene.meshes.push(MeshLayer::new(m));
    }
    for m in &cages {
        scene.meshes.push(MeshLayer::wireframe(m, [200, 40, 40]));
    }
    let options = RenderOptions {
        width: 900,
        height: 600,
        azimuth: 60.0,
        elevation: 30.0,
        supersample: 2,
        title: Some("rest, twist, bend, taper (4x1x1 lattice, 3 levels)".into()),
        ..Default::default()
    };
    let path = out.join("bar_deformations.png");
    write_png(&path, &render(&scene, &options)?)?;
    println!("wrote {}", path.display());
    Ok(())
}

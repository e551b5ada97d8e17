//! A barbell lattice (MacCracken & Joy 1996, §5, fig. 10: two blocks joined
//! by a thin handle, a lattice no single box can be): two 3×3×3 blocks of
//! unit cells joined by a 3-cell handle of one cell's cross-section, around
//! a dumbbell surface. The right block is turned a quarter turn about the
//! bar's axis and lifted; the handle carries the twist and the bend.
//!
//! Inputs: none. Outputs in `target/examples-out/`: `barbell.obj` (the
//! deformed dumbbell) and `barbell.png` (rest and deformed, lattices as
//! wireframes). Run with `cargo run --release --example 22_barbell`.

mod common;

use subdyn::ffd::{Ffd, FfdParams};
use subdyn::lattice::hexahedra;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};

/// Radius of the dumbbell at `x`: two balls of radius 1.2 centred at
/// `x = 1.5` and `x = 7.5` joined by a bar of radius 0.3.
fn radius(x: f64) -> f64 {
    let ball = |c: f64| (1.2f64 * 1.2 - (x - c) * (x - c)).max(0.0).sqrt();
    ball(1.5)
        .max(ball(7.5))
        .max(if (1.5..=7.5).contains(&x) { 0.3 } else { 0.0 })
}

/// The dumbbell as a surface of revolution about the line `y = z = 1.5`,
/// `n` stations along `x` (poles at both ends) by `m` around.
fn dumbbell(n: usize, m: usize) -> subdyn::Result<PolyMesh> {
    let (x0, x1) = (0.3, 8.7);
    let mut pos = vec![Point3::new(x0, 1.5, 1.5)];
    for i in 1..n {
        // Stations crowd towards the poles (cosine spacing).
        let t = 0.5 - 0.5 * (std::f64::consts::PI * i as f64 / n as f64).cos();
        let x = x0 + (x1 - x0) * t;
        let r = radius(x).max(0.02);
        for j in 0..m {
            let a = std::f64::consts::TAU * j as f64 / m as f64;
            pos.push(Point3::new(x, 1.5 + r * a.cos(), 1.5 + r * a.sin()));
        }
    }
    pos.push(Point3::new(x1, 1.5, 1.5));
    let last = (pos.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * m + j % m) as u32;
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for j in 0..m {
        faces.push(vec![0, ring(1, j + 1), ring(1, j)]);
        for i in 1..n - 1 {
            faces.push(vec![
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            ]);
        }
        faces.push(vec![last, ring(n - 1, j), ring(n - 1, j + 1)]);
    }
    PolyMesh::from_faces(pos, &faces)
}

fn main() -> subdyn::Result<()> {
    let out_dir = common::output_dir()?;
    // The cells of a 9×3×3 grid kept: both blocks and the handle's middle column.
    let id = |i: usize, j: usize, k: usize| (i + 10 * (j + 4 * k)) as u32;
    let mut all = Vec::new();
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..10 {
                all.push(Point3::new(i as f64, j as f64, k as f64));
            }
        }
    }
    let mut hexes = Vec::new();
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..9 {
                if (3..6).contains(&i) && (j, k) != (1, 1) {
                    continue;
                }
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    // Only the grid points the cells use.
    let mut used = vec![u32::MAX; all.len()];
    let mut positions = Vec::new();
    for h in &mut hexes {
        for v in h.iter_mut() {
            if used[*v as usize] == u32::MAX {
                used[*v as usize] = positions.len() as u32;
                positions.push(all[*v as usize]);
            }
            *v = used[*v as usize];
        }
    }
    let lat = hexahedra(positions, &hexes)?;
    let model = dumbbell(120, 48)?;
    let ffd = Ffd::new(
        &lat,
        &model.positions,
        &FfdParams {
            levels: 3,
            ..Default::default()
        },
    )?;
    println!("{:?}", ffd.report);
    let axis = Point3::new(0.0, 1.5, 1.5);
    let moved_lattice: Vec<Point3> = lat
        .positions
        .iter()
        .map(|p| {
            // The right block (x ≥ 6) turns a quarter about the bar's axis and
            // rises; the handle (3 ≤ x ≤ 6) blends in between.
            let t = ((p.x - 3.0) / 3.0).clamp(0.0, 1.0);
            let a = std::f64::consts::FRAC_PI_2 * t;
            let (y, z) = (p.y - axis.y, p.z - axis.z);
            Point3::new(
                p.x,
                axis.y + a.cos() * y - a.sin() * z,
                axis.z + a.sin() * y + a.cos() * z + 1.5 * t,
            )
        })
        .collect();
    let moved = ffd.deform(&moved_lattice)?;
    let mut out = model.clone();
    out.positions = moved;
    let path = out_dir.join("barbell.obj");
    subdyn::io::write_mesh(&path, &out, None)?;
    println!("wrote {}", path.display());
    let shift = |m: &PolyMesh, pos: &[Point3], dy: f64| {
        let mut m = m.clone();
        m.positions = pos.iter().map(|p| p + Vector3::new(0.0, dy, 0.0)).collect();
        m
    };
    let cage = lat.boundary_mesh()?;
    let meshes = [
        shift(&model, &model.positions, 0.0),
        shift(&out, &out.positions, 5.0),
    ];
    let cages = [
        shift(&cage, &lat.positions, 0.0),
        shift(&cage, &moved_lattice, 5.0),
    ];
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
        azimuth: 30.0,
        elevation: 30.0,
        supersample: 2,
        title: Some("barbell lattice: rest and twisted + lifted right block (3 levels)".into()),
        ..Default::default()
    };
    let path = out_dir.join("barbell.png");
    write_png(&path, &render(&scene, &options)?)?;
    println!("wrote {}", path.display());
    Ok(())
}

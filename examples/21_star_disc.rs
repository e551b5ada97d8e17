//! A star-shaped deformation of a disc with a cylinder lattice (MacCracken &
//! Joy 1996, §5: a cylindrical lattice of ten hexahedra around a
//! decagonal prism; its outer control points pushed out and pulled in in
//! turn). The lattice's central cell is a decagonal prism (not a
//! hexahedron); every vertex of it has valence 3, so refinement makes
//! hexahedra only, ten of them around the axis (an extraordinary edge).
//!
//! Inputs: none. Outputs in `target/examples-out/`: `disc_star.obj` (the
//! deformed disc) and `disc_star.png` (rest disc and star, lattices as
//! wireframes). Run with `cargo run --release --example 21_star_disc`.

mod common;

use subdyn::ffd::{Ffd, FfdParams};
use subdyn::lattice::cylinder;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};

/// A closed disc of radius `r` between heights `z0` and `z1`: concentric
/// rings on both caps (a triangle fan at the centre), quads on the side.
fn disc(r: f64, z0: f64, z1: f64, rings: usize, segments: usize) -> subdyn::Result<PolyMesh> {
    let mut pos = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let ring_start =
        |cap: usize, i: usize| (cap * (1 + rings * segments) + 1 + (i - 1) * segments) as u32;
    for (cap, z) in [z0, z1].into_iter().enumerate() {
        pos.push(Point3::new(0.0, 0.0, z));
        for i in 1..=rings {
            for s in 0..segments {
                let a = std::f64::consts::TAU * s as f64 / segments as f64;
                let rho = r * i as f64 / rings as f64;
                pos.push(Point3::new(rho * a.cos(), rho * a.sin(), z));
            }
        }
        let centre = (cap * (1 + rings * segments)) as u32;
        let n = segments as u32;
        for s in 0..n {
            let t = (s + 1) % n;
            let r1 = ring_start(cap, 1);
            let mut tri = vec![centre, r1 + s, r1 + t];
            if cap == 0 {
                tri.reverse();
            }
            faces.push(tri);
            for i in 1..rings {
                let (a, b) = (ring_start(cap, i), ring_start(cap, i + 1));
                let mut q = vec![a + s, b + s, b + t, a + t];
                if cap == 0 {
                    q.reverse();
                }
                faces.push(q);
            }
        }
    }
    let (lo, hi) = (ring_start(0, rings), ring_start(1, rings));
    let n = segments as u32;
    for s in 0..n {
        let t = (s + 1) % n;
        faces.push(vec![lo + s, lo + t, hi + t, hi + s]);
    }
    PolyMesh::from_faces(pos, &faces)
}

fn main() -> subdyn::Result<()> {
    let out_dir = common::output_dir()?;
    let model = disc(1.0, 0.1, 0.4, 24, 96)?;
    let segments = 10;
    let lat = cylinder(1.4, 0.5, segments, 1)?;
    let ffd = Ffd::new(
        &lat,
        &model.positions,
        &FfdParams {
            levels: 3,
            ..Default::default()
        },
    )?;
    println!("{:?}", ffd.report);
    // Vertex v of the cylinder: layer v / 2n, inner ring (v % 2n < n) or
    // outer ring, segment v % n. Outer points alternate out and in.
    let n = segments;
    let star: Vec<Point3> = lat
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            if v % (2 * n) < n {
                return *p;
            }
            let s = if (v % n) % 2 == 0 { 1.6 } else { 0.75 };
            Point3::new(s * p.x, s * p.y, p.z)
        })
        .collect();
    let moved = ffd.deform(&star)?;
    let mut out = model.clone();
    out.positions = moved;
    let path = out_dir.join("disc_star.obj");
    subdyn::io::write_mesh(&path, &out, None)?;
    println!("wrote {}", path.display());
    let shift = |m: &PolyMesh, pos: &[Point3], dx: f64| {
        let mut m = m.clone();
        m.positions = pos.iter().map(|p| p + Vector3::new(dx, 0.0, 0.0)).collect();
        m
    };
    let cage = lat.boundary_mesh()?;
    let layers = [
        shift(&model, &model.positions, 0.0),
        shift(&out, &out.positions, 4.5),
    ];
    let cages = [shift(&cage, &lat.positions, 0.0), shift(&cage, &star, 4.5)];
    let mut scene = Scene::default();
    for m in &layers {
        scene.meshes.push(MeshLayer::new(m));
    }
    for m in &cages {
        scene.meshes.push(MeshLayer::wireframe(m, [200, 40, 40]));
    }
    let options = RenderOptions {
        width: 900,
        height: 500,
        azimuth: 0.0,
        elevation: 55.0,
        supersample: 2,
        title: Some("disc in a 10-segment cylinder lattice: rest and star (3 levels)".into()),
        ..Default::default()
    };
    let path = out_dir.join("disc_star.png");
    write_png(&path, &render(&scene, &options)?)?;
    println!("wrote {}", path.display());
    Ok(())
}

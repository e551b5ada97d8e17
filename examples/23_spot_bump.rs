//! A local bump on Spot with a locally refined octree lattice
//! (multiresolution-lattice FFD paper, §2.2: octree rules applied only to a
//! user-chosen cell). The cow is refined twice (Catmull-Clark), wrapped in
//! an automatic 4³ octree lattice with empty cells culled; the cell holding
//! the top of the back is refined by the octree rules, and only the control
//! points that refinement created are pushed up. Its face and edge
//! neighbours become non-hexahedral cells (type-2 and type-4 cells after
//! Catmull-Clark refinement), which the embedding handles by tetrahedra.
//!
//! Input: a mesh path (default `../shared/data/meshes/spot.obj`; when it is
//! absent, the Spot mesh built into `subdyn::examples`). Outputs in
//! `target/examples-out/`: `spot_bump.obj` and `spot_bump.png` (rest and bumped,
//! the lattice's hull as a wireframe). Run with
//! `cargo run --release --example 23_spot_bump [-- MESH]`.

mod common;

use subdyn::ffd::{Ffd, FfdParams};
use subdyn::lattice::{BoxLatticeParams, box_lattice, locally_refined};
use subdyn::math::{Point3, Vector3, bbox_diagonal};
use subdyn::mesh::PolyMesh;
use subdyn::render::{MeshLayer, RenderOptions, Scene, render, write_png};
use subdyn::subdivision::{RefineOptions, Refiner};

fn main() -> subdyn::Result<()> {
    let out_dir = common::output_dir()?;
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/data/meshes/spot.obj".into());
    let cage = if std::path::Path::new(&path).exists() {
        println!("reading {path}");
        subdyn::io::read_mesh(&path)?
    } else {
        println!("{path} not found: using subdyn::examples::demo_truth()");
        subdyn::examples::demo_truth()?
    };
    let refiner = Refiner::new(&cage, &RefineOptions::default())?;
    let h = refiner.refine_uniform(2)?;
    let model = h.mesh(2, h.stencil_to_level(2)?.apply(&cage.positions)?);
    let d = bbox_diagonal(&model.positions);
    let lat = box_lattice(
        &model.positions,
        &BoxLatticeParams {
            octree_levels: 2,
            ..Default::default()
        },
    )?;
    // The top of the back (the highest vertex in a thin slice across the
    // body at 65 % of its length from the nose), and the lattice cell
    // holding it (by the cells' vertex boxes; they are axis-aligned here).
    let (lo, hi) = subdyn::math::bounding_box(&model.positions)
        .ok_or_else(|| subdyn::Error::input("empty model"))?;
    let z = lo.z + 0.65 * (hi.z - lo.z);
    let top = model
        .positions
        .iter()
        .copied()
        .filter(|p| (p.z - z).abs() < 0.02 * d)
        .max_by(|a, b| a.y.total_cmp(&b.y))
        .ok_or_else(|| subdyn::Error::input("no vertex in the slice"))?;
    let t = &lat.topology;
    let cell = (0..t.num_cells())
        .find(|&c| {
            let vs = t.cell_vertices.row(c);
            (0..3).all(|k| {
                let (lo, hi) = vs.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &v| {
                    let x = lat.positions[v as usize][k];
                    (lo.min(x), hi.max(x))
                });
                (lo..=hi).contains(&top[k])
            })
        })
        .ok_or_else(|| subdyn::Error::input("no lattice cell holds the top vertex"))?;
    println!("bump centre {top:?}");
    let (local, report) = locally_refined(&lat, &[cell])?;
    println!(
        "lattice: {} cells; cell {cell} refined → {:?}",
        t.num_cells(),
        report
    );
    let ffd = Ffd::new(
        &local,
        &model.positions,
        &FfdParams {
            levels: 2,
            ..Default::default()
        },
    )?;
    println!("{:?}", ffd.report);
    // Push up the points local refinement created (edge, face and cell
    // points of the chosen cell), most at the top vertex.
    let sigma = 0.1 * d;
    let moved: Vec<Point3> = local
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            if v < lat.num_vertices() {
                return *p;
            }
            let w = (-(p - top).norm_squared() / (sigma * sigma)).exp();
            p + Vector3::new(0.0, 0.2 * d * w, 0.0)
        })
        .collect();
    let mut out = model.clone();
    out.positions = ffd.deform(&moved)?;
    let moved_vertices = out
        .positions
        .iter()
        .zip(&model.positions)
        .filter(|(a, b)| (*a - *b).norm() > 1e-3 * d)
        .count();
    println!(
        "{moved_vertices} of {} vertices moved by more than 0.1 % of the diagonal",
        model.num_vertices()
    );
    let path = out_dir.join("spot_bump.obj");
    subdyn::io::write_mesh(&path, &out, None)?;
    println!("wrote {}", path.display());
    let shift = |m: &PolyMesh, pos: &[Point3], dx: f64| {
        let mut m = m.clone();
        m.positions = pos
            .iter()
            .map(|p| p + Vector3::new(0.0, 0.0, -dx))
            .collect();
        m
    };
    let hull = local.boundary_mesh()?;
    let dx = 0.8 * d;
    let meshes = [
        shift(&model, &model.positions, 0.0),
        shift(&out, &out.positions, dx),
    ];
    let cages = [
        shift(&hull, &local.positions, 0.0),
        shift(&hull, &moved, dx),
    ];
    let mut scene = Scene::default();
    for m in &meshes {
        scene.meshes.push(MeshLayer::new(m));
    }
    for m in &cages {
        scene.meshes.push(MeshLayer::wireframe(m, [200, 40, 40]));
    }
    let options = RenderOptions {
        width: 1000,
        height: 550,
        azimuth: 90.0,
        elevation: 15.0,
        supersample: 2,
        title: Some("Spot: rest and a local bump from one locally refined lattice cell".into()),
        ..Default::default()
    };
    let path = out_dir.join("spot_bump.png");
    write_png(&path, &render(&scene, &options)?)?;
    println!("wrote {}", path.display());
    Ok(())
}

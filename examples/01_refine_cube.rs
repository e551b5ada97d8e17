//! Refine the embedded unit cube three levels with one composed stencil table
//! and move the result to the limit surface.
//!
//! Inputs: none (the cube is built in). Output: `cube_l3_limit.obj` in
//! `target/examples-out/`. Run with `cargo run --release --example 01_refine_cube`.

mod common;

use subdyn::limit::limit_stencil;
use subdyn::subdivision::{RefineOptions, Refiner};

fn main() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let cage = subdyn::examples::cube();
    // Topology once, without positions.
    let refiner = Refiner::new(&cage, &RefineOptions::default())?;
    let hierarchy = refiner.refine_uniform(3)?;
    // P_3 = S P_0 and its limit positions L P_0: two sparse products.
    let s = hierarchy.stencil_to_level(3)?;
    let limit = limit_stencil(&hierarchy, 3)?;
    println!(
        "level 3: {} vertices; S has {} weights, the limit table {}",
        s.num_rows(),
        s.num_entries(),
        limit.num_entries()
    );
    let on_limit = limit.apply(&cage.positions)?;
    let mesh = hierarchy.mesh(3, on_limit);
    let path = out.join("cube_l3_limit.obj");
    subdyn::io::write_mesh(&path, &mesh, None)?;
    println!("wrote {}", path.display());
    Ok(())
}

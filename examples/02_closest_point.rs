//! Project points onto the limit surface of a control mesh: the spring-force
//! engine of fitting.
//!
//! Input: a control mesh (default: the embedded cube; or a path as the first
//! argument, e.g. `../shared/data/meshes/spot.obj`). Output: a summary on
//! stdout. Run with `cargo run --release --example 02_closest_point [MESH]`.

use std::time::Instant;

use subdyn::limit::{ClosestPointEngine, ClosestPointParams, LimitEvaluator};
use subdyn::math::Point3;
use subdyn::subdivision::{RefineOptions, Refiner};

fn main() -> subdyn::Result<()> {
    let cage = match std::env::args().nth(1) {
        Some(path) => subdyn::io::read_mesh(path)?,
        None => subdyn::examples::cube(),
    };
    let refiner = Refiner::new(&cage, &RefineOptions::default())?;
    let eval = LimitEvaluator::new(&refiner);
    // Points at a known distance from the surface: limit samples pushed out along the normal.
    let offset = 0.01 * subdyn::math::bbox_diagonal(&cage.positions);
    let mut queries: Vec<Point3> = Vec::new();
    for f in 0..cage.num_faces() {
        let n = cage.face(f).len();
        let (u, v) = if n == 4 { (0.3, 0.7) } else { (0.15, 0.35) };
        let s = eval.evaluate(f, u, v, &cage.positions)?;
        queries.push(s.p + offset * s.normal());
    }
    let t = Instant::now();
    let engine =
        ClosestPointEngine::new(&refiner, &cage.positions, &ClosestPointParams::default())?;
    let built = t.elapsed();
    let t = Instant::now();
    let found = engine.closest_points(&queries)?;
    let queried = t.elapsed();
    // The pushed-out sample is at distance `offset`, so the closest point can
    // only be as close or closer (closer where the surface is concave).
    let farther = found
        .iter()
        .map(|c| c.distance - offset)
        .fold(f64::MIN, f64::max);
    let closer = found
        .iter()
        .filter(|c| c.distance < offset * (1.0 - 1e-9))
        .count();
    println!(
        "{} queries: engine built in {:.3} s, queries took {:.3} s; \
         max(distance − offset) = {farther:.2e}; {closer} found a closer surface point",
        queries.len(),
        built.as_secs_f64(),
        queried.as_secs_f64()
    );
    // Fitting moves the control points every step: only positions are redone.
    let mut engine = engine;
    let moved: Vec<Point3> = cage
        .positions
        .iter()
        .map(|p| p + 0.1 * offset * p.coords)
        .collect();
    let t = Instant::now();
    engine.set_positions(&moved)?;
    println!(
        "set_positions after a small move: {:.3} s",
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

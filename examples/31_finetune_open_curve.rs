//! Exact fine tuning of an open cubic B-spline subdivision curve: a quadratic
//! α (control values on the edges of the control polygon) grows from 0.6 to
//! 1.6 along a wave, and the new curve `Q(t) = P(0) + ∫ α P'` is computed
//! exactly as a degree-5 B-spline with knots of multiplicity 3 (no solver).
//! Then `Q'(t) = α(t) P'(t)` is checked at 1,000 parameters.
//!
//! Inputs: none (the wave is built in). Output: `finetune_open_curve.png` in
//! `target/examples-out/` (grey: control polygon, blue: original curve, red:
//! fine-tuned curve). Run with
//! `cargo run --release --example 31_finetune_open_curve`.

mod common;

use subdyn::finetune::{alpha_from_values, comparison_layers, curve_picture, exact_finetune};
use subdyn::math::Point3;
use subdyn::render::write_png;
use subdyn::subdivision::{CurveScheme, CurveTopology};

fn main() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let n = 12;
    let polygon: Vec<Point3> = (0..n)
        .map(|i| Point3::new(i as f64, if i % 2 == 0 { 0.0 } else { 1.5 }, 0.0))
        .collect();
    let topo = CurveTopology::new(CurveScheme::Cubic, n, false)?;
    // Quadratic α on a cubic curve: one value per edge (n − 1 edges).
    let values: Vec<f64> = (0..topo.num_legs())
        .map(|e| 0.6 + e as f64 / (topo.num_legs() - 1) as f64)
        .collect();
    let alpha = alpha_from_values(&topo, 2, &values)?;
    let exact = exact_finetune(&topo, &polygon, &alpha)?;
    let dq = exact.curve.derivative_curve()?;
    let mut worst: f64 = 0.0;
    for i in 0..=1000 {
        let t = topo.num_spans() as f64 * i as f64 / 1000.0;
        let p_prime = topo.limit_stencil(&[t], 1)?.apply(&polygon)?[0].coords;
        let want = alpha.value(&topo, t)? * p_prime;
        worst = worst.max((dq.point(t).coords - want).norm() / want.norm().max(1.0));
    }
    println!(
        "Q: degree {}, knot multiplicity {}, {} control points; max |Q' - α P'| / max(1, |α P'|) over 1,001 parameters: {worst:.1e}",
        exact.degree,
        exact.multiplicity,
        exact.curve.control_points.len()
    );
    let layers = comparison_layers(&topo, &polygon, &exact.curve)?;
    let picture = curve_picture(
        &layers,
        "alpha 0.6 -> 1.6: blue original, red fine-tuned",
        900,
        500,
    )?;
    let path = out.join("finetune_open_curve.png");
    write_png(&path, &picture)?;
    println!("wrote {}", path.display());
    Ok(())
}

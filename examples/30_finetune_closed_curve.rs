//! Fine tuning of a closed quadratic (Chaikin) subdivision curve with one
//! stretched leg, in the spirit of figure 14 of the fine-tuning paper: a
//! linear α is 1.5 on the bottom leg and 1 elsewhere; the exact curve
//! `Q' = α P'` does not close, and the spring energy (13) (k_l : k_a = 1 : 2)
//! closes it.
//!
//! Inputs: none (an octagonal control polygon is built in). Output:
//! `finetune_closed_curve.png` in `target/examples-out/` (grey: control
//! polygon, blue: original limit curve, red: fine-tuned curve, green: the
//! exact but unclosed `Q`). Run with
//! `cargo run --release --example 30_finetune_closed_curve`.

mod common;

use subdyn::finetune::{
    CurveFinetune, CurveFinetuneParams, alpha_from_values, comparison_layers, curve_layer,
    curve_picture,
};
use subdyn::math::Point3;
use subdyn::render::write_png;
use subdyn::subdivision::{CurveScheme, CurveTopology};

fn main() -> subdyn::Result<()> {
    let out = common::output_dir()?;
    let polygon: Vec<Point3> = [
        (0., 0.),
        (2., 0.),
        (3., 1.),
        (3., 3.),
        (2., 4.),
        (0., 4.),
        (-1., 3.),
        (-1., 1.),
    ]
    .iter()
    .map(|&(x, y)| Point3::new(x, y, 0.0))
    .collect();
    let topo = CurveTopology::new(CurveScheme::Quadratic, polygon.len(), true)?;
    // Linear α on a quadratic curve: one value per edge; edge 0 is the bottom leg.
    let mut values = vec![1.0; topo.num_legs()];
    values[0] = 1.5;
    let alpha = alpha_from_values(&topo, 1, &values)?;
    let params = CurveFinetuneParams {
        fixed_point: 8,
        ..CurveFinetuneParams::default()
    };
    let tuner = CurveFinetune::new(&topo, &polygon, &alpha, &params)?;
    let (curve, report) = tuner.solve()?;
    println!(
        "degree {} (knot multiplicity {}), {} control points; {} Levenberg-Marquardt iterations ({}), energy {:.3e} -> {:.3e}; gap {:.3} -> {:.1e}; {:.1} ms",
        report.degree,
        report.multiplicity,
        report.num_control_points,
        report.iterations,
        report.termination,
        report.initial_energy,
        report.final_energy,
        report.gap_before,
        report.gap_after,
        report.seconds * 1e3
    );
    let mut layers = comparison_layers(&topo, &polygon, &curve)?;
    layers.insert(1, curve_layer(&tuner.exact().curve, [40, 170, 60], 1));
    let picture = curve_picture(
        &layers,
        "bottom leg x1.5: blue original, red fine-tuned, green unclosed",
        800,
        640,
    )?;
    let path = out.join("finetune_closed_curve.png");
    write_png(&path, &picture)?;
    println!("wrote {}", path.display());
    Ok(())
}

//! Fine tuning of a closed quadratic (Chaikin) subdivision curve with one
//! stretched leg, in the spirit of figure 14 of the fine-tuning paper: a
//! linear α is 1.5 on the bottom leg and 1 elsewhere; the exact curve
//! `Q' = α P'` does not close, and the spring energy (13) (k_l : k_a = 1 : 2)
//! closes it.
//!
//! Inputs: none (an octagonal control polygon is built in). Output:
//! `finetune_closed_curve.png` in the current directory (grey: control
//! polygon, blue: original limit curve, red: fine-tuned curve, green: the
//! exact but unclosed `Q`). Run with
//! `cargo run --release --example 30_finetune_closed_curve`.

use std::path::Path;

use subdyn::finetune::{
    CurveFinetune, CurveFinetuneParams, CurveLayer, alpha_from_values, curve_picture,
};
use subdyn::math::Point3;
use subdyn::render::write_png;
use subdyn::subdivision::{CurveScheme, CurveTopology};

fn main() -> subdyn::Result<()> {
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
    let ts: Vec<f64> = (0..=20 * polygon.len()).map(|i| i as f64 / 20.0).collect();
    let original = topo.limit_stencil(&ts, 0)?.apply(&polygon)?;
    let mut closed_polygon = polygon.clone();
    closed_polygon.push(polygon[0]);
    let unclosed = tuner.exact().curve.samples(20 * polygon.len());
    let tuned = curve.samples(20 * polygon.len());
    let layers = [
        CurveLayer {
            points: closed_polygon,
            color: [170, 170, 170],
            width: 1,
            marks: true,
        },
        CurveLayer {
            points: unclosed,
            color: [40, 170, 60],
            width: 1,
            marks: false,
        },
        CurveLayer {
            points: original,
            color: [60, 90, 200],
            width: 3,
            marks: false,
        },
        CurveLayer {
            points: tuned,
            color: [220, 60, 40],
            width: 3,
            marks: false,
        },
    ];
    let picture = curve_picture(
        &layers,
        "bottom leg x1.5: blue original, red fine-tuned, green unclosed",
        800,
        640,
    )?;
    write_png(Path::new("finetune_closed_curve.png"), &picture)?;
    println!("wrote finetune_closed_curve.png");
    Ok(())
}

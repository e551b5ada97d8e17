//! `subdyn finetune curve CURVE.json --values V.json -o OUT.json`: the
//! fine-tuned curve `Q' = α P'` (exact for open curves, closed again by the
//! spring energy (13) for closed ones). File formats: `subdyn::finetune`'s
//! `curve_io` module docs.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use subdyn::finetune::{
    CurveFinetune, CurveFinetuneParams, FinetuneMethod, comparison_layers, curve_json,
    curve_picture, read_alpha, read_curve, write_json,
};
use subdyn::math::Real;
use subdyn::render::{check_png_path, write_png};

use super::common::{Written, about_file, check_output_dir, warn, write_report};

/// Arguments of `subdyn finetune curve`.
#[derive(Debug, Args)]
#[command(
    after_help = "CURVE.json: {\"scheme\": \"quadratic\"|\"cubic\", \"closed\": bool, \
    \"points\": [[x,y] or [x,y,z], ...]}. V.json: {\"degree\": 1|2|3, \"values\": [...]}, one \
    positive value per edge (leg i joins points i and i+1) or per vertex: quadratic curves take \
    degree 1 and 3 on edges, 2 on vertices; cubic curves degree 1 and 3 on vertices, 2 on edges."
)]
pub struct CurveArgs {
    /// The curve (JSON).
    #[arg(value_name = "CURVE.json")]
    pub input: PathBuf,
    /// Control values of α (JSON).
    #[arg(long, value_name = "V.json")]
    pub values: PathBuf,
    /// Output B-spline (JSON).
    #[arg(short, long, value_name = "OUT.json")]
    pub output: PathBuf,
    /// Spring coefficients k_l,k_a of eq. 13 (closed curves).
    #[arg(long, value_name = "KL,KA", default_value = "1,2")]
    pub k: String,
    /// Index of the fixed control point of the fine-tuned polygon (closed curves).
    #[arg(long, value_name = "I", default_value_t = 0)]
    pub fix: usize,
    /// Minimiser of energy (13): lm (Levenberg-Marquardt) or ncg (argmin's nonlinear CG).
    #[arg(long, value_name = "lm|ncg", default_value = "lm")]
    pub method: FinetuneMethod,
    /// Write a JSON report (energies, iterations, gaps, time).
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Draw the original and the fine-tuned curve (top view) to a PNG.
    #[arg(long, value_name = "P.png")]
    pub png: Option<PathBuf>,
    /// No warnings (the summary and the written files are still printed, as
    /// every verb does).
    #[arg(short, long)]
    pub quiet: bool,
}

/// Parses `KL,KA`.
fn spring_coefficients(text: &str) -> anyhow::Result<(Real, Real)> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let parse = |s: &str| {
        s.parse::<Real>()
            .ok()
            .filter(|x| x.is_finite() && *x >= 0.0)
    };
    match parts.as_slice() {
        [a, b] => match (parse(a), parse(b)) {
            (Some(a), Some(b)) if a + b > 0.0 => Ok((a, b)),
            _ => anyhow::bail!("--k {text}: expected two non-negative numbers, not both zero"),
        },
        _ => anyhow::bail!("--k {text}: expected KL,KA"),
    }
}

/// Runs `subdyn finetune curve`.
pub fn run(args: &CurveArgs) -> anyhow::Result<()> {
    let (k_length, k_angle) = spring_coefficients(&args.k)?;
    if let Some(png) = &args.png {
        check_png_path(png)?;
    }
    check_output_dir(&args.output)?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    let (topo, points) = read_curve(&args.input).map_err(|e| about_file(e, &args.input))?;
    let alpha = read_alpha(&args.values, &topo).map_err(|e| about_file(e, &args.values))?;
    let params = CurveFinetuneParams {
        k_length,
        k_angle,
        fixed_point: args.fix,
        method: args.method,
        ..CurveFinetuneParams::default()
    };
    let tuner = CurveFinetune::new(&topo, &points, &alpha, &params)?;
    let (curve, report) = tuner.solve()?;
    if !report.converged {
        warn(
            args.quiet,
            &format!(
                "the solver stopped before converging: {}",
                report.termination
            ),
        );
    }
    write_json(&args.output, &curve_json(&curve, topo.closed))?;
    let mut written = Written::new();
    written.add(&args.output, "fine-tuned curve");
    if let Some(path) = &args.report {
        write_report(
            path,
            &json!({
                "input": args.input.display().to_string(),
                "closed": topo.closed,
                "curve_degree": topo.degree(),
                "alpha_degree": alpha.degree,
                "degree": report.degree,
                "multiplicity": report.multiplicity,
                "control_points": report.num_control_points,
                "variables": report.num_variables,
                "method": format!("{:?}", args.method),
                "iterations": report.iterations,
                "initial_energy": report.initial_energy,
                "final_energy": report.final_energy,
                "gradient_norm": report.gradient_norm,
                "converged": report.converged,
                "termination": report.termination,
                "gap_before": report.gap_before,
                "gap_after": report.gap_after,
                "seconds": report.seconds,
                "energies": report.energies,
            }),
        )?;
        written.add(path, "report");
    }
    if let Some(path) = &args.png {
        let layers = comparison_layers(&topo, &points, &curve)?;
        let picture = curve_picture(&layers, "blue: original  red: fine-tuned", 800, 600)?;
        write_png(path, &picture)?;
        written.add(path, "picture");
    }
    written.print_after(&format!(
        "fine-tuned curve: degree {}, {} control points, {} iterations, energy {:.3e} -> {:.3e}, gap {:.1e} -> {:.1e}, {:.1} ms\n",
        report.degree,
        report.num_control_points,
        report.iterations,
        report.initial_energy,
        report.final_energy,
        report.gap_before,
        report.gap_after,
        report.seconds * 1e3
    ))
}

//! Fine tuning of subdivision curves and surfaces by scaling derivatives
//! (fine-tuning paper, §4.2–4.4).
//!
//! Curves: a new curve `Q` with `Q'(t) = α(t) P'(t)`, closed curves closed
//! again by the spring energy (13) minimised by Levenberg-Marquardt
//! (`linalg::levenberg_marquardt` on `linalg`'s 3 × 3-block sparse Cholesky,
//! re-exported here; `angle_curvature`) or argmin's nonlinear CG
//! (`method`: which of the two). Files:
//! `curve_alpha` (α from control values), `curve_exact` (exact product and
//! integral as a B-spline), `curve_bspline` (evaluation), `curve_energy`
//! (eq. 13), `curve_frames` (fixed point and rotation), `curve_solver` (argmin
//! glue), `curve_gauss_newton` (eq. 13 as residuals), `curve` (params,
//! precompute, solve, report), `curve_io` (JSON files), `curve_picture`
//! (top-view PNG).
//!
//! Surfaces: Doo-Sabin to non-uniform Catmull-Clark conversion (`convert`),
//! edge loops, the spring energy (14) (`surface_energy`, `surface_targets`)
//! minimised by Levenberg-Marquardt (`surface_gauss_newton`) or nonlinear
//! conjugate gradient (`surface_solve`, `surface`).

mod angle_curvature;
mod convert;
mod curve;
mod curve_alpha;
mod curve_bspline;
mod curve_energy;
mod curve_exact;
mod curve_frames;
mod curve_gauss_newton;
mod curve_io;
mod curve_picture;
mod curve_solver;
mod edge_loops;
mod method;
mod surface;
mod surface_energy;
mod surface_gauss_newton;
mod surface_solve;
mod surface_targets;

pub use crate::linalg::{
    Cholesky, CholeskyPattern, FORCING_MAX, LeastSquares, LmParams, LmRun, LmTimings,
    REFINEMENT_ITERATIONS, RELATIVE_RESIDUAL, Residuals, levenberg_marquardt,
    preconditioned_solution,
};
pub use convert::{Conversion, ConvertedEdge, conversion_weight, doo_sabin_to_non_uniform};
pub use curve::{CurveFinetune, CurveFinetuneParams, CurveFinetuneReport, finetune_curve};
pub use curve_alpha::{ScalarFunction, ValuesOn, alpha_from_values, values_on};
pub use curve_bspline::BSplineCurve;
pub use curve_energy::{SpringTargets, joint_angle, joint_angle_gradients, wrap_angle};
pub use curve_exact::{
    ExactFinetune, closed_spline, exact_finetune, finetuned_spans, spline_from_spans,
};
pub use curve_io::{curve_json, read_alpha, read_curve, write_json};
pub use curve_picture::{CurveLayer, comparison_layers, curve_layer, curve_picture};
pub use edge_loops::{EdgeLoop, edge_loops};
pub use method::FinetuneMethod;
pub use surface::{SurfaceFineTune, SurfaceFineTuneParams, SurfaceFineTuneReport, SurfaceScheme};
pub use surface_energy::{SpringEnergy, angle_and_gradients, joint_angles};
pub use surface_targets::{LegKind, loop_targets};

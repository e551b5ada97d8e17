//! Fine tuning of subdivision surfaces by scaling derivatives: Doo-Sabin to
//! non-uniform Catmull-Clark conversion, edge loops, the spring energy (14)
//! minimised by nonlinear conjugate gradient.

mod convert;
mod edge_loops;
mod surface;
mod surface_energy;
mod surface_solve;
mod surface_targets;

pub use convert::{Conversion, ConvertedEdge, conversion_weight, doo_sabin_to_non_uniform};
pub use edge_loops::{EdgeLoop, edge_loops};
pub use surface::{SurfaceFineTune, SurfaceFineTuneParams, SurfaceFineTuneReport, SurfaceScheme};
pub use surface_energy::{SpringEnergy, angle_and_gradients, joint_angles};
pub use surface_targets::{LegKind, loop_targets};

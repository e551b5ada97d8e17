//! Fitting dynamic Catmull-Clark surfaces to point clouds (Qin, Mandal,
//! Vemuri 1998, §6): data springs pull the surface, the thin plate under
//! tension keeps it fair, and when the model settles above the tolerance it
//! is subdivided and the fit continues at the finer level.

mod cloud_levels;
mod creases;
mod driver;
pub mod fairness;
pub mod init;
mod levels;
mod params;
pub mod quality;
pub mod recover;
pub mod refine_marks;
mod report;
mod sampling;
mod start;
mod system;
mod untangle;

pub use creases::Crease;
pub use driver::{FitResult, crease_options, fit_point_cloud, fit_screened_cloud};
pub use params::{FitParams, Refinement, ToleranceStat};
pub use report::{ErrorStats, FitReport, LevelReport, Untangling};
pub use start::{FitRun, FitStart, MIN_FIT_POINTS, fit_from_start, stat_name};

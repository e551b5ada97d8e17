//! Simulated range scans: poses, ray casting against the ground truth with
//! noise, dropout and outliers, the PLY writer with view ids, the sidecar.

mod args;
mod camera;
mod cmd;
mod ply;
mod record;
mod simulate;

pub use args::{ScanArgs, ScanJob};
pub use cmd::{run, run_scan};
pub use ply::Precision;
pub use simulate::NormalKind;

//! Dynamic Catmull-Clark surfaces (Qin, Mandal, Vemuri 1998): quadrature over
//! the limit surface, mass / damping / thin-plate-under-tension stiffness
//! matrices assembled over the control points, and a preconditioned conjugate
//! gradient solver.

mod elements;
mod matrices;
mod pcg;
mod quadrature;
mod sample_rows;

pub use elements::{
    PatchElements, parameter_area, patch_damping_matrix, patch_stiffness_and_damping,
    patch_stiffness_matrix, stiffness_and_damping_elements,
};
pub use matrices::{MaterialParams, damping_matrix, mass_matrix, stiffness_matrix};
pub use pcg::{PcgParams, PcgReport, pcg};
pub use quadrature::{Quadrature, gauss_legendre, patch_samples, quadrature};
pub use sample_rows::{SampleRows, patch_sample_rows};

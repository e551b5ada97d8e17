//! Dynamic Catmull-Clark surfaces (Qin, Mandal, Vemuri 1998): quadrature over
//! the limit surface, mass / damping / thin-plate-under-tension stiffness
//! matrices assembled over the control points, implicit time integration
//! (first and second order), and two linear solvers: preconditioned
//! conjugate gradients and, for steps that reuse their matrix, sparse
//! Cholesky (`linalg`'s scalar factor, re-exported here).

mod elements;
mod implicit;
mod integrator;
mod matrices;
mod pcg;
mod quadrature;
mod sample_rows;

pub use crate::linalg::SparseCholesky;
pub use elements::{
    PatchElements, parameter_area, patch_damping_matrix, patch_matrices,
    patch_stiffness_and_damping, patch_stiffness_matrix, stiffness_and_damping_elements,
};
pub use implicit::ImplicitSystem;
pub use integrator::{LinearSolver, StepReport, SurfaceDynamics};
pub use matrices::{MaterialParams, damping_matrix, mass_matrix, stiffness_matrix};
pub use pcg::{PcgParams, PcgReport, pcg};
pub use quadrature::{Quadrature, gauss_legendre, patch_samples, quadrature, square_rule};
pub use sample_rows::{SampleRows, patch_sample_rows};

//! Forces on a dynamic subdivision surface, each distributed to the control
//! points as `Jᵀ f` (Qin, Mandal, Vemuri 1998, §5): data springs from scan
//! points with robust weights, image boundary springs from volumes,
//! inflation, and a point-drag spring.

mod image;
mod inflation;
mod patch_assembly;
mod robust;
mod springs;

pub use image::{BoundaryModel, ImageField, Offset};
pub use inflation::inflation_force;
pub use patch_assembly::{PatchAssembly, PatchRows, RowSprings};
pub use robust::{RobustKernel, robust_weights};
pub use springs::{SpringSystem, drag_spring, row_springs, spread_point_springs, spring_system};

//! Uniform Catmull-Clark refinement: topology refined once, every level a
//! stencil table `P_{k+1} = S_k P_k`.

mod catmull_clark;
mod refine_topology;
mod refiner;

pub use catmull_clark::refine_stencil;
pub use refine_topology::refine_topology;
pub use refiner::{BoundaryRule, Hierarchy, RefineOptions, Refiner};

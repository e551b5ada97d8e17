//! Refinement as stencil tables: uniform Catmull-Clark (`P_{k+1} = S_k P_k`),
//! Doo-Sabin, and non-uniform Catmull-Clark with knot intervals.

mod catmull_clark;
mod doo_sabin;
mod non_uniform;
mod refine_topology;
mod refiner;

pub use catmull_clark::refine_stencil;
pub use doo_sabin::{
    DooSabinHierarchy, DooSabinStep, doo_sabin_faces, doo_sabin_refine, doo_sabin_step,
    doo_sabin_weight,
};
pub use non_uniform::{NonUniformHierarchy, check_intervals, non_uniform_step};
pub use refine_topology::refine_topology;
pub use refiner::{BoundaryRule, Hierarchy, RefineOptions, Refiner};

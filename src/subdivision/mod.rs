//! Refinement as stencil tables: uniform Catmull-Clark (`P_{k+1} = S_k P_k`),
//! local refinement of marked faces, Doo-Sabin, non-uniform Catmull-Clark with knot intervals, and uniform
//! quadratic / cubic B-spline subdivision curves (`curves`).

mod catmull_clark;
mod curves;
mod doo_sabin;
mod local_refine;
mod non_uniform;
mod refine_topology;
mod refiner;
mod uniform;

pub use catmull_clark::refine_stencil;
pub use curves::{CurveScheme, CurveTopology, bernstein, bspline_to_bezier, span_basis};
pub use doo_sabin::{
    DooSabinHierarchy, DooSabinStep, doo_sabin_faces, doo_sabin_refine, doo_sabin_step,
    doo_sabin_weight,
};
pub use local_refine::{CornerImage, LocalRefinement, close_marks, refine_marked};
pub use non_uniform::{NonUniformHierarchy, check_intervals, non_uniform_step};
pub use refine_topology::refine_topology;
pub use refiner::{BoundaryRule, Hierarchy, RefineOptions, Refiner, TriangleRule};
pub use uniform::{
    MAX_FACES, MAX_LEVELS, check_refinement_memory, check_uniform_size, estimated_faces,
    uniform_positions,
};

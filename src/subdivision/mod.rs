//! Uniform Catmull-Clark refinement: topology refined once, every level a
//! stencil table `P_{k+1} = S_k P_k`; uniform quadratic / cubic B-spline
//! subdivision curves (`curves`).

mod catmull_clark;
mod curves;
mod refine_topology;
mod refiner;

pub use catmull_clark::refine_stencil;
pub use curves::{CurveScheme, CurveTopology, bernstein, bspline_to_bezier, span_basis};
pub use refine_topology::refine_topology;
pub use refiner::{BoundaryRule, Hierarchy, RefineOptions, Refiner};

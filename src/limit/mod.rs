//! The limit surface: vertex limit masks, exact evaluation at `(face, u, v)`
//! with derivatives as stencil rows, tessellation and closest points.

mod bspline;
mod closest;
mod evaluator;
mod interpolate;
mod limit_stencil;
mod local_eval;
mod param;
mod patch;
mod patch_table;
mod tessellate;
mod vertex_masks;

pub use bspline::{cubic_basis, patch_weights};
pub use closest::{ClosestPoint, ClosestPointEngine, ClosestPointParams};
pub use evaluator::{LimitEvaluator, LimitPoint, LimitStencils, MAX_EXACT_RING, Sample};
pub use interpolate::interpolate_limit_points;
pub use limit_stencil::{limit_stencil, limit_tangent_stencils};
pub(crate) use param::chain as chain_rule;
pub use patch::SampleStencil;
pub use patch_table::{PatchPoint, PatchTable, QuadtreeCache, TREE_DEPTH};
pub use tessellate::{Tessellation, limit_surface_mesh, tessellate};
pub use vertex_masks::CornerKind;

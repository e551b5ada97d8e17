//! Distances between geometry: exact point-to-triangle-mesh distances with a
//! BVH, ray casts, one-sided and symmetric statistics, Chamfer and Hausdorff
//! distances, normal consistency — on meshes, point clouds and Catmull-Clark
//! limit surfaces.
//!
//! - [`TriangleBvh`] (`bvh`, `bvh_build`, `bvh_collapse`, `bvh_closest`, `bvh_ray`): closest
//!   point and first ray hit;
//!   leaf tests in `triangle` ([`closest_point_on_triangle`], [`ray_triangle`]).
//! - [`self_intersecting_pairs`] (`self_intersections`): the pairs of a
//!   mesh's triangles that cross, on a uniform grid (no hierarchy).
//! - [`distances`] (`batch`): many queries in parallel.
//! - [`DistanceStats`], [`percentile`] (`stats`).
//! - [`area_samples`] (`sampling`): area-weighted points on triangles.
//! - [`Surface`] (`surface`): a mesh or a limit surface, measured exactly.
//! - [`compare()`], [`compare_points`] (`compare`): the comparison of `A` with
//!   a reference `B`, with every definition in the module docs.

mod batch;
mod bvh;
mod bvh_build;
mod bvh_closest;
mod bvh_collapse;
mod bvh_ray;
mod compare;
mod sampling;
mod self_intersections;
mod stats;
mod surface;
mod triangle;

pub use batch::distances;
pub use bvh::{Hit, Nearest, TriangleBvh};
pub use compare::{CompareParams, Comparison, OneSided, compare, compare_points};
pub use sampling::area_samples;
pub use self_intersections::self_intersecting_pairs;
pub use stats::{DistanceStats, percentile};
pub use surface::{Surface, SurfacePoint};
pub use triangle::{
    PreparedTriangle, RAY_BARY_SLACK, RAY_PARALLEL_COS, closest_point_on_triangle, ray_triangle,
    triangle_normal,
};

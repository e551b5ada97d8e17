//! Geometry containers: polygon meshes and point clouds.

mod point_cloud;
mod poly_mesh;
mod simplify;
mod triangles;

pub use point_cloud::PointCloud;
pub use poly_mesh::PolyMesh;
pub(crate) use poly_mesh::check_finite;
pub use simplify::simplified;
pub use triangles::split_quads;

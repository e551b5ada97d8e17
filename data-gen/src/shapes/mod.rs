//! The built-in shapes: closed meshes with exact ground truth.

mod anvil;
mod bulb;
mod catalog;
mod cuboids;
mod genus2;
mod implicit;
mod machined;
mod marching_tets;
mod quad_sphere;
mod relax;
mod revolve;
mod sdf;

pub use catalog::{ShapeKind, ShapeParams, build_shape, surface_deviation};

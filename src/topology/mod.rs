//! Connectivity without positions: edges, adjacency, boundaries, valences,
//! crease sharpness.

mod level;
mod sharpness;
mod union_find;

pub use level::{Level, NONE, VertexRing, face_of_corner};
pub use sharpness::{
    CreaseMethod, SHARPNESS_INFINITE, Sharpness, VertexRule, decrement, find_edge,
};
pub use union_find::UnionFind;

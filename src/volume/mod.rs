//! Volumes (MRI, CT, slice stacks) as scalar grids, and the image processing
//! that turns them into forces: smoothing, edge potentials, sampling.

mod edges;
mod gaussian;
mod grid;
mod threshold;

pub use edges::edge_potential;
pub use gaussian::{gaussian_smoothed, gaussian_smoothed_owned};
pub use grid::Volume;
pub use threshold::otsu_threshold;

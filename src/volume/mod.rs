//! Volumes (MRI, CT, slice stacks) as scalar grids, and the image processing
//! that turns them into forces: smoothing, edge potentials, sampling.

mod grid;

pub use grid::Volume;

//! Volume lattices of arbitrary topology and their Catmull-Clark volume
//! refinement with boundary control (MacCracken & Joy 1996).
//!
//! A [`Lattice`] is control points on a [`LatticeTopology`] (faces as vertex
//! loops, cells as face lists, derived edges and incidences) with
//! [`BoundaryTags`]. [`LatticeHierarchy`] refines it `n` times: one
//! [`StencilTable`](crate::stencil::StencilTable) per level, their product
//! `S_n`, and each refined level's topology, whose cells are all
//! [`TypeNCells`].
//!
//! ```
//! use subdyn::lattice::{box_grid, LatticeHierarchy};
//! use subdyn::math::Point3;
//! let lat = box_grid(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
//! let h = LatticeHierarchy::new(&lat, 2).unwrap();
//! let s2 = h.stencil_to_level(2).unwrap();
//! let p2 = s2.apply(&lat.positions).unwrap();
//! assert_eq!(p2.len(), 125); // a 4×4×4-cell grid, still exactly the cube
//! ```

mod box_lattice;
mod builders;
mod hierarchy;
#[allow(clippy::module_inception)]
mod lattice;
mod local_refine;
mod octree;
mod refine_topology;
mod rules;
mod shrink;
mod topology;

pub use box_lattice::{BoxKind, BoxLatticeParams, bounding_frame, box_lattice};
pub use builders::{HEX_FACES, LatticeBuilder, box_grid, cylinder, extrude, hexahedra};
pub use hierarchy::{LatticeHierarchy, LatticeLevel, MAX_LATTICE_LEVELS};
pub use lattice::{BoundaryTags, Lattice, cell_volume, check_geometry};
pub use local_refine::{LocalRefineReport, locally_refined};
pub use octree::{octree_refined, octree_stencil};
pub use refine_topology::{TypeNCells, refined_cells, refined_topology};
pub use rules::{refined_tags, refinement_stencil};
pub use shrink::{ShrinkReport, shrunk_box_lattice};
pub use topology::{Csr, LatticeTopology, NO_CELL};

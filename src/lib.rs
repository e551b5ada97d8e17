//! # subdyn
//!
//! Recover and edit smooth shapes with Catmull-Clark subdivision.
//!
//! The pipeline in ten lines:
//!
//! ```
//! use subdyn::{io, subdivision::{Refiner, RefineOptions}};
//! let cage = subdyn::examples::cube();                      // or io::read_mesh("cage.obj")
//! let refiner = Refiner::new(&cage, &RefineOptions::default()).unwrap(); // topology, once
//! let hierarchy = refiner.refine_uniform(2).unwrap();       // levels + stencils S_k
//! let s = hierarchy.stencil_to_level(2).unwrap();           // P_2 = S P_0, one CSR table
//! let p2 = s.apply(&cage.positions).unwrap();               // one sparse product
//! assert_eq!(p2.len(), hierarchy.level(2).num_vertices);
//! # let _ = io::MeshFormat::Obj;
//! ```
//!
//! Modules: [`math`] (scalar and point types), [`error`], [`memory`] (the memory budget), [`allocator`] (the binary's one-line out-of-memory exit), [`mesh`] (polygon
//! meshes, point clouds), [`io`] (OBJ, PLY, OFF, XYZ), [`topology`] (edges,
//! adjacency, tags), [`subdivision`] (Catmull-Clark refinement, B-spline curves), [`stencil`]
//! (CSR stencil tables), [`limit`] (limit masks, exact evaluation, closest point),
//! [`metrics`] (point-to-mesh distances, Chamfer, Hausdorff), [`render`]
//! (software rasteriser for pictures), [`finetune`] (fine tuning of curves by
//! scaling derivatives), [`lattice`] (volume lattices, Catmull-Clark volume
//! refinement), [`solid`] (dynamic subdivision solids and sculpting tools).

#![warn(missing_docs)]

pub mod allocator;
pub mod dynamics;
pub mod error;
pub mod examples;
pub mod ffd;
pub mod finetune;
pub mod fit;
pub mod forces;
pub mod io;
pub mod lattice;
pub mod limit;
pub mod linalg;
pub mod math;
pub mod memory;
pub mod mesh;
pub mod metrics;
pub mod render;
pub mod solid;
pub mod stencil;
pub mod subdivision;
pub mod topology;
pub mod volume;

pub use error::{Error, Result};

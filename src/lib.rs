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
//! The main job, fitting a scan (what `subdyn fit` does with its defaults):
//!
//! ```
//! use subdyn::fit::{FitParams, FitStart, crease_options, fit_from_start, init::InitParams};
//! let scan = subdyn::examples::demo_scan()?;                 // or io::read_points("scan.ply")
//! let start = FitStart::Method(InitParams::default());       // the automatic initial cage
//! let run = fit_from_start(&scan, &start, &FitParams::default(), &mut |_, _, _| {})?;
//! let last = run.result.report.levels.last().unwrap();       // per level: error, steps, time
//! assert!(last.error.p95_pct < 0.2);  // % of the diagonal; the scan has 0.1 % noise
//! let tags = crease_options(&run.result.creases);            // sharp edges found in the scan
//! let (surface, _normals) =
//!     subdyn::limit::limit_surface_mesh(&run.result.control, &tags, 4, false)?;
//! assert!(surface.num_faces() > run.result.control.num_faces()); // io::write_mesh(...)
//! # Ok::<(), subdyn::Error>(())
//! ```
//!
//! Modules, from the foundation up: [`math`] (scalar and point types),
//! [`error`], [`memory`] (the memory budget), [`allocator`] (the binary's
//! one-line out-of-memory exit), [`mesh`] (polygon meshes, point clouds),
//! [`io`] (OBJ, PLY, OFF, XYZ), [`examples`] (small embedded meshes and the
//! demo scan), [`topology`] (edges, adjacency, tags), [`subdivision`]
//! (Catmull-Clark refinement, B-spline curves), [`stencil`] (CSR stencil
//! tables), [`linalg`] (conjugate gradients, orderings, sparse Cholesky,
//! Levenberg-Marquardt), [`limit`] (limit masks, exact evaluation, closest
//! point), [`metrics`] (point-to-mesh distances, Chamfer, Hausdorff),
//! [`volume`] (scalar grids and image forces' preprocessing), [`dynamics`]
//! (mass, damping and stiffness of dynamic Catmull-Clark surfaces, implicit
//! integration), [`forces`] (data springs, image and inflation forces),
//! [`fit`] (fitting point clouds and recovering shapes from volumes),
//! [`lattice`] (volume lattices, Catmull-Clark volume refinement), [`ffd`]
//! (free-form deformation with lattices), [`solid`] (dynamic subdivision
//! solids and sculpting tools), [`finetune`] (fine tuning of Doo-Sabin and
//! Catmull-Clark curves and surfaces), [`render`] (software rasteriser for
//! pictures). `docs/ARCHITECTURE.md` has the layering and the design notes.

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

pub use error::{Error, InputError, InputKind, Result};

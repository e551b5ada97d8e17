//! Dynamic Catmull-Clark subdivision solids and their sculpting tools
//! (McDonnell & Qin, "Dynamic sculpting and animation of free-form
//! subdivision solids").
//!
//! A [`Solid`] holds the control lattice `p`, the mass points `d = A p` of its
//! level-`L` MacCracken–Joy refinement, a [`SpringNetwork`] (normal and
//! virtual springs) on that lattice, lumped masses and damping, and the
//! free/fixed partition `d = A₁ p₁ + A₂ p₂`. It steps with the paper's
//! explicit integrator ([`Solid::step_explicit`]) or backward Euler with CG
//! ([`Solid::step_implicit`]). Tools: ropes, fix / free, stiffness and
//! damping, make plastic ([`tools`]), extrude and trim ([`edit`]).
//!
//! ```
//! use subdyn::lattice::box_grid;
//! use subdyn::math::Point3;
//! use subdyn::solid::{Solid, SolidParams};
//! let cube = box_grid(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0), [2, 2, 2]).unwrap();
//! let mut solid = Solid::new(&cube, SolidParams { level: 1, ..SolidParams::default() }).unwrap();
//! assert_eq!(solid.mass_points().len(), 125);
//! let corner = solid.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
//! solid.add_rope(corner, Point3::new(1.5, 1.5, 1.5), 50.0, 0.0).unwrap();
//! for _ in 0..10 {
//!     solid.step_implicit(0.01).unwrap();
//! }
//! assert!(solid.mass_points()[corner].x > 1.0);
//! ```

pub mod edit;
mod explicit;
mod implicit;
mod model;
mod params;
mod products;
mod reduced;
mod springs;
pub mod tools;

pub use edit::{extrude_face, extruded_topology, extrusion_offset, trim_cell, trimmed_topology};
pub use explicit::StepReport;
pub use model::{MAX_SOLID_LEVEL, Solid, lumped_masses};
pub use params::{ExplicitScheme, ImplicitPreconditioner, SolidParams, check_value};
pub use reduced::MAX_DENSE_UNKNOWNS;
pub use springs::{SpringHessians, SpringNetwork, Stiffness};
pub use tools::Rope;

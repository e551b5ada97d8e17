//! Initial control meshes for fitting a point cloud (`subdyn fit --init auto`).
//!
//! Qin, Mandal and Vemuri (1998) start every fit from a control mesh made by
//! hand; [`initial_mesh`] makes one from the points. Clouds above 50,000
//! points are thinned, outliers are dropped ([`outliers`]) and the principal
//! axes computed ([`frame`]); then:
//!
//! | method | when | cage |
//! |---|---|---|
//! | [`InitKind::Closed`] ([`ellipsoid`]) | closed, genus 0 | 26 vertices, 24 quads on the points' principal-axes ellipsoid |
//! | [`InitKind::Open`] ([`height_grid`]) | one range view | open quad grid over the principal plane, trimmed to the footprint |
//! | [`InitKind::Occupancy`] ([`occupancy`]) | closed, any genus | smoothed boundary of the points' voxel occupancy, carved between facing sheets ([`carve`]), made manifold ([`voxel_repair`]) |
//! | [`InitKind::Auto`] ([`detect`]) | default | open if the layered fraction is below 0.3; else occupancy, replaced by the ellipsoid when its genus is 0 |
//!
//! ```no_run
//! use subdyn::fit::init::{initial_mesh, InitParams};
//! let cloud = subdyn::io::read_points("bun045.ply")?;
//! let (cage, report) = initial_mesh(&cloud, &InitParams::default())?;
//! println!("{}: {}", report.chosen, report.reason);
//! subdyn::io::write_mesh("cage.obj", &cage, None)?;
//! # Ok::<(), subdyn::Error>(())
//! ```

pub mod carve;
pub mod detect;
pub mod ellipsoid;
pub mod footprint;
pub mod frame;
pub mod gaps;
pub mod height_grid;
mod initial;
pub mod normals;
pub mod occupancy;
pub mod outliers;
mod params;
pub mod sampling;
pub mod surface;
pub mod voxel_repair;
pub mod voxel_surface;
pub mod voxels;

pub use detect::{Closedness, closedness};
pub use frame::{MIN_POINTS, PrincipalFrame};
pub use initial::{MAX_INIT_POINTS, initial_mesh};
pub use params::{InitKind, InitParams, InitReport, MAX_RESOLUTION};
pub use surface::{SurfaceTopology, signed_volume, surface_topology};

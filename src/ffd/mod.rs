//! Free-form deformation with Catmull-Clark volume lattices of arbitrary
//! topology (MacCracken & Joy 1996): model vertices are embedded in the
//! cells of the `n`-times refined lattice, and the deformation is one sparse
//! map `v = B p` with `B = W S_n`.
//!
//! ```
//! use subdyn::ffd::{Ffd, FfdParams};
//! use subdyn::lattice::box_grid;
//! use subdyn::math::Point3;
//! let lat = box_grid(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0), [2, 2, 2]).unwrap();
//! let model = vec![Point3::new(0.3, 0.4, 0.5), Point3::new(2.0, 0.0, 0.0)];
//! let mut ffd = Ffd::new(&lat, &model, &FfdParams { levels: 2, ..Default::default() }).unwrap();
//! assert_eq!(ffd.report.outside, 1);
//! assert!((ffd.deformed[0] - model[0]).norm() < 1e-12); // unmoved lattice: identity
//! let top = lat.positions.len() - 1;
//! let moved = lat.positions[top] + nalgebra::Vector3::new(0.0, 0.0, 0.5);
//! ffd.move_control(&[(top, moved)]).unwrap(); // touches only B's column `top`
//! ```

mod cell_coords;
mod cell_index;
mod deform;
mod embed;
mod hierarchical;

pub use cell_coords::{CellCoords, cell_coords, cell_triangles, trilinear_coords};
pub use cell_index::CellIndex;
pub use deform::{Ffd, FfdParams, FfdReport};
pub use embed::{Embedding, embedding, embedding_in_cells};
pub use hierarchical::{Enclosing, LayeredFfd};

//! Stencil tables: sparse CSR matrices that map control points to anything
//! (refined vertices, limit samples, derivatives). See `StencilTable`.

mod assemble;
mod min_degree;
mod nested_dissection;
mod table;

pub use assemble::Elements;
pub(crate) use nested_dissection::nested_dissection;
pub use table::{RowBuilder, StencilTable};

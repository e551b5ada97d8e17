//! Stencil tables: sparse CSR matrices that map control points to anything
//! (refined vertices, limit samples, derivatives). See `StencilTable`.

mod assemble;
mod csr;
mod table;

pub use assemble::Elements;
pub use table::{RowBuilder, StencilTable};

//! Stencil tables: sparse CSR matrices that map control points to anything
//! (refined vertices, limit samples, derivatives). See `StencilTable`.

mod table;

pub use table::{RowBuilder, StencilTable};

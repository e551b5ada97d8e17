//! Stencil tables: sparse CSR matrices that map control points to anything
//! (refined vertices, limit samples, derivatives). See `StencilTable`.

mod assemble;
mod csr;
mod primvar;
mod table;

pub use assemble::Elements;
pub use primvar::Primvar;
pub use table::{RowBuilder, StencilTable};

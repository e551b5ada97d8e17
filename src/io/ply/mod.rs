//! Stanford PLY: ASCII, binary little endian and binary big endian.
//!
//! The header is parsed in full ([`header`]); the body is read by one generic
//! routine ([`body`]) over a stream of values ([`values`]) that hides the
//! encoding. Scanner headers (`obj_info` lines, `range_grid` elements of lists)
//! and any other element or property are skipped. The writer is [`mod@write`].

mod body;
mod header;
mod layout;
mod values;
mod write;

use std::path::Path;

use self::header::{Encoding, parse_header};
use self::values::{AsciiValues, BinaryValues};
use super::raw::RawGeometry;
use crate::error::Result;

pub(crate) use self::write::write_ply;

/// Parses a PLY file: the `vertex` element (`x y z`, and `nx ny nz` when all
/// three are present) and the `face` element's `vertex_indices` (or
/// `vertex_index`) list; a file without a `face` element has no faces.
pub(crate) fn parse_ply(bytes: &[u8], path: &Path) -> Result<RawGeometry> {
    let header = parse_header(bytes, path)?;
    let data = &bytes[header.body_start..];
    match header.encoding {
        Encoding::Ascii => {
            let mut values = AsciiValues::new(data, header.header_lines + 1);
            body::read_body(&mut values, &header, path)
        }
        Encoding::BinaryLittleEndian => {
            body::read_body(&mut BinaryValues::<false>::new(data), &header, path)
        }
        Encoding::BinaryBigEndian => {
            body::read_body(&mut BinaryValues::<true>::new(data), &header, path)
        }
    }
}

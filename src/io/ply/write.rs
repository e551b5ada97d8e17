//! The PLY writer: binary little endian, coordinates as `double`.

use std::io::Write;

use crate::io::write::Geometry;

/// Bytes gathered before each hand-over to the underlying writer.
const CHUNK: usize = 1 << 16;

/// Writes a binary little-endian PLY: a `vertex` element with `double x y z`
/// (and `nx ny nz` when there are normals) and, for a mesh, a `face` element
/// with a `list uchar int vertex_indices` (`list uint int` when a face has
/// more than 255 vertices).
pub(crate) fn write_ply(w: &mut dyn Write, geometry: &Geometry) -> std::io::Result<()> {
    if i32::try_from(geometry.positions.len()).is_err() {
        return Err(std::io::Error::other(
            "PLY output stores indices as int: at most 2^31 - 1 vertices",
        ));
    }
    writeln!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by subdyn"
    )?;
    writeln!(w, "element vertex {}", geometry.positions.len())?;
    for name in ["x", "y", "z"] {
        writeln!(w, "property double {name}")?;
    }
    if geometry.normals.is_some() {
        for name in ["nx", "ny", "nz"] {
            writeln!(w, "property double {name}")?;
        }
    }
    let wide = geometry.faces().any(|f| f.len() > 255);
    if geometry.mesh.is_some() {
        writeln!(w, "element face {}", geometry.num_faces())?;
        let count = if wide { "uint" } else { "uchar" };
        writeln!(w, "property list {count} int vertex_indices")?;
    }
    writeln!(w, "end_header")?;

    let mut buf = Vec::with_capacity(CHUNK + 64);
    for (i, p) in geometry.positions.iter().enumerate() {
        for c in [p.x, p.y, p.z] {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        if let Some(n) = geometry.normals.and_then(|n| n.get(i)) {
            for c in [n.x, n.y, n.z] {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        flush_full(w, &mut buf)?;
    }
    for face in geometry.faces() {
        if wide {
            buf.extend_from_slice(&(face.len() as u32).to_le_bytes());
        } else {
            buf.push(face.len() as u8);
        }
        for &v in face {
            // Fits: the vertex count was checked against i32::MAX above.
            buf.extend_from_slice(&(v as i32).to_le_bytes());
            flush_full(w, &mut buf)?;
        }
    }
    w.write_all(&buf)
}

/// Hands `buf` to `w` once it holds a chunk.
fn flush_full(w: &mut dyn Write, buf: &mut Vec<u8>) -> std::io::Result<()> {
    if buf.len() >= CHUNK {
        w.write_all(buf)?;
        buf.clear();
    }
    Ok(())
}

//! Object File Format (OFF): reader and writer.
//!
//! Read: a header word ending in `OFF` (`OFF`, `NOFF`, `COFF`, `CNOFF`, `STOFF`, …;
//! the counts may follow on the same line), `#` comments, the counts line
//! `vertices faces [edges]`, one vertex per line (`x y z`, then `nx ny nz` for
//! `N…OFF`, then colours or texture coordinates, which are skipped) and one face
//! per line (`n i1 … in`, 0-based, trailing colour columns skipped).
//! Four-dimensional (`4OFF`, `nOFF`) and binary OFF are rejected.

use std::io::Write;
use std::path::Path;

use super::raw::RawGeometry;
use super::text::{content_lines, finite_normal, finite_point, parse_count, parse_triple};
use super::write::{Geometry, write_point_line};
use crate::error::{Error, Result};

/// Parses OFF text; `NOFF` normals are kept.
pub(crate) fn parse_off(bytes: &[u8], path: &Path) -> Result<RawGeometry> {
    let mut lines = content_lines(bytes, path);
    let (header_line, header) = lines
        .next()
        .transpose()?
        .ok_or_else(|| Error::parse(path, 0, "no OFF header: the file has only comments"))?;
    let mut tokens = header.split_ascii_whitespace();
    let keyword = tokens.next().unwrap_or_default();
    let has_normals = header_flags(path, header_line, keyword)?;
    if tokens.clone().next() == Some("BINARY") {
        return Err(Error::parse(
            path,
            header_line,
            "binary OFF is not supported",
        ));
    }
    // The counts may sit on the header line itself.
    let (counts_line, counts) = if tokens.clone().next().is_some() {
        (header_line, tokens.collect::<Vec<_>>())
    } else {
        let (line, text) = lines.next().transpose()?.ok_or_else(|| {
            Error::parse(path, header_line, "the file ends before the counts line")
        })?;
        (line, text.split_ascii_whitespace().collect())
    };
    if counts.len() < 2 {
        return Err(Error::parse(
            path,
            counts_line,
            "expected the counts line `vertices faces [edges]`",
        ));
    }
    let num_vertices = parse_count(path, counts_line, counts[0], "the vertex count")?;
    let num_faces = parse_count(path, counts_line, counts[1], "the face count")?;

    let mut raw = RawGeometry::new();
    let cap = bytes.len() / 8;
    raw.positions.reserve(num_vertices.min(cap));
    let mut normals = Vec::new();
    let mut last_line = counts_line;
    for vertex in 0..num_vertices {
        let (line, text) = lines.next().transpose()?.ok_or_else(|| {
            let msg = format!("expected {num_vertices} vertices, but the file ends after {vertex}");
            Error::parse(path, last_line, msg)
        })?;
        last_line = line;
        let mut tokens = text.split_ascii_whitespace();
        let c = parse_triple(path, line, &mut tokens, "a vertex position")?;
        raw.positions.push(finite_point(path, line, vertex, c)?);
        if has_normals {
            let n = parse_triple(path, line, &mut tokens, "a normal")?;
            normals.push(finite_normal(path, line, vertex, n)?);
        }
    }
    raw.face_offsets.reserve(num_faces.min(cap));
    for face in 0..num_faces {
        let (line, text) = lines.next().transpose()?.ok_or_else(|| {
            let msg = format!("expected {num_faces} faces, but the file ends after {face}");
            Error::parse(path, last_line, msg)
        })?;
        last_line = line;
        let mut tokens = text.split_ascii_whitespace();
        let size = parse_count(
            path,
            line,
            tokens.next().unwrap_or_default(),
            "the face size",
        )?;
        for _ in 0..size {
            let token = tokens.next().ok_or_else(|| {
                Error::parse(
                    path,
                    line,
                    format!("face {face} should list {size} vertices"),
                )
            })?;
            let index = parse_count(path, line, token, "a vertex index")?;
            if index >= num_vertices {
                return Err(Error::parse(
                    path,
                    line,
                    format!(
                        "face {face} refers to vertex {index}, but the file has {num_vertices} vertices"
                    ),
                ));
            }
            raw.face_vertices.push(index as u32);
        }
        raw.close_face(path, line, face)?;
    }
    if let Some((line, _)) = lines.next().transpose()? {
        return Err(Error::parse(
            path,
            line,
            format!(
                "unexpected data after the last face; the counts line says \
                 {num_vertices} vertices and {num_faces} faces"
            ),
        ));
    }
    if has_normals {
        raw.normals = Some(normals);
    }
    Ok(raw)
}

/// Checks the header keyword and tells whether vertices carry normals.
fn header_flags(path: &Path, line: usize, keyword: &str) -> Result<bool> {
    let prefix = keyword.strip_suffix("OFF").ok_or_else(|| {
        Error::parse(
            path,
            line,
            format!("expected the header `OFF`, found `{keyword}`"),
        )
    })?;
    if prefix.contains('4') || prefix.contains('n') {
        return Err(Error::parse(
            path,
            line,
            format!("`{keyword}`: only three-dimensional OFF is supported"),
        ));
    }
    if let Some(bad) = prefix.chars().find(|c| !matches!(c, 'S' | 'T' | 'C' | 'N')) {
        return Err(Error::parse(
            path,
            line,
            format!("unknown OFF header `{keyword}` (unexpected `{bad}`)"),
        ));
    }
    Ok(prefix.contains('N'))
}

/// Writes `OFF` (or `NOFF` with normals), the counts and 0-based faces.
pub(crate) fn write_off(w: &mut dyn Write, geometry: &Geometry) -> std::io::Result<()> {
    let header = if geometry.normals.is_some() {
        "NOFF"
    } else {
        "OFF"
    };
    writeln!(w, "{header}")?;
    writeln!(w, "{} {} 0", geometry.positions.len(), geometry.num_faces())?;
    for (i, p) in geometry.positions.iter().enumerate() {
        write_point_line(w, p, geometry.normals.and_then(|n| n.get(i)))?;
    }
    for face in geometry.faces() {
        write!(w, "{}", face.len())?;
        for v in face {
            write!(w, " {v}")?;
        }
        w.write_all(b"\n")?;
    }
    Ok(())
}

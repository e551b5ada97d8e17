//! Wavefront OBJ: a small reader that keeps polygons as they are and names the
//! line of every error, and the writer.
//!
//! Read: `v x y z [w] [r g b]` (columns past `z` ignored), `vn`, and `f` with
//! `a`, `a/b`, `a//c` or `a/b/c` corners; negative indices count back from the
//! last vertex defined so far. Groups and objects (`g`, `o`) merge into one
//! mesh; every other statement (`vt`, `s`, `usemtl`, `l`, …) is skipped (OpenSubdiv's
//! `t` tag lines are read by [`read_obj_tags`](super::read_obj_tags)).

use std::io::Write;
use std::path::Path;

use super::raw::RawGeometry;
use super::text::{content_lines, finite_normal, finite_point, parse_triple};
use super::write::{Geometry, write_real};
use crate::error::{Error, Result};

/// Parses OBJ text. Normals are kept only when there is exactly one `vn` per `v`.
pub(crate) fn parse_obj(bytes: &[u8], path: &Path) -> Result<RawGeometry> {
    let mut raw = RawGeometry::new();
    let mut normals = Vec::new();
    // The largest positive index seen and its line: positive indices may refer
    // forward, so they are checked against the final vertex count at the end.
    let mut max_index: Option<(u64, usize)> = None;
    let mut num_faces = 0;
    for item in content_lines(bytes, path) {
        let (line, text) = item?;
        let mut tokens = text.split_ascii_whitespace();
        match tokens.next() {
            Some("v") => {
                let c = parse_triple(path, line, &mut tokens, "a vertex position")?;
                let vertex = raw.positions.len();
                raw.positions.push(finite_point(path, line, vertex, c)?);
            }
            Some("vn") => {
                let c = parse_triple(path, line, &mut tokens, "a normal")?;
                normals.push(finite_normal(path, line, normals.len(), c)?);
            }
            Some("f") => {
                for corner in tokens {
                    let index = corner_index(path, line, corner, raw.positions.len())?;
                    if max_index.is_none_or(|(m, _)| u64::from(index) > m) {
                        max_index = Some((u64::from(index), line));
                    }
                    raw.face_vertices.push(index);
                }
                raw.close_face(path, line, num_faces)?;
                num_faces += 1;
            }
            _ => {}
        }
    }
    if let Some((index, line)) = max_index {
        let n = raw.positions.len();
        if index as usize >= n {
            return Err(Error::parse(
                path,
                line,
                format!(
                    "face refers to vertex index {}, but the file has only {n} vertices",
                    index + 1
                ),
            ));
        }
    }
    if !normals.is_empty() && normals.len() == raw.positions.len() {
        raw.normals = Some(normals);
    }
    Ok(raw)
}

/// The 0-based vertex index of one face corner `a`, `a/b`, `a//c` or `a/b/c`,
/// with `defined` vertices read so far (for negative, relative indices).
fn corner_index(path: &Path, line: usize, corner: &str, defined: usize) -> Result<u32> {
    let token = corner.split('/').next().unwrap_or(corner);
    let value: i64 = token.parse().map_err(|_| {
        Error::parse(
            path,
            line,
            format!("expected a vertex index in face corner `{corner}`"),
        )
    })?;
    let index = match value {
        0 => {
            return Err(Error::parse(
                path,
                line,
                "index 0 is not valid (OBJ indices start at 1)",
            ));
        }
        v if v > 0 => v - 1,
        v => {
            let back = v.unsigned_abs();
            if back > defined as u64 {
                return Err(Error::parse(
                    path,
                    line,
                    format!(
                        "relative index {v} reaches before the first vertex \
                         ({defined} vertices defined so far)"
                    ),
                ));
            }
            (defined as u64 - back) as i64
        }
    };
    u32::try_from(index).map_err(|_| {
        Error::parse(
            path,
            line,
            format!("vertex index {value} is too large for this library (at most 2^32)"),
        )
    })
}

/// Writes `v` lines, `vn` lines when `normals` are given, and `f` lines with
/// 1-based indices (`f a//a …` when there are normals).
pub(crate) fn write_obj(w: &mut dyn Write, geometry: &Geometry) -> std::io::Result<()> {
    writeln!(w, "# written by subdyn")?;
    for p in geometry.positions {
        write_vector_line(w, "v", p.x, p.y, p.z)?;
    }
    if let Some(normals) = geometry.normals {
        for n in normals {
            write_vector_line(w, "vn", n.x, n.y, n.z)?;
        }
    }
    for face in geometry.faces() {
        w.write_all(b"f")?;
        for &v in face {
            let v = u64::from(v) + 1;
            if geometry.normals.is_some() {
                write!(w, " {v}//{v}")?;
            } else {
                write!(w, " {v}")?;
            }
        }
        w.write_all(b"\n")?;
    }
    for &(i, j, sharpness) in geometry.creases {
        write!(w, "t crease 2/1/0 {i} {j} ")?;
        write_real(w, sharpness)?;
        w.write_all(b"\n")?;
    }
    Ok(())
}

/// One `key x y z` line.
fn write_vector_line(w: &mut dyn Write, key: &str, x: f64, y: f64, z: f64) -> std::io::Result<()> {
    w.write_all(key.as_bytes())?;
    for c in [x, y, z] {
        w.write_all(b" ")?;
        write_real(w, c)?;
    }
    w.write_all(b"\n")
}

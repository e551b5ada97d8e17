//! The PLY body: vertices (positions, optional normals), faces (the
//! `vertex_indices` list) and every other element skipped, in header order.
//! Which element and property is which comes from [`Layout`].

use std::path::Path;

use super::header::{Element, Header, PropertyKind, Scalar};
use super::layout::{Layout, Slot};
use super::values::{Fail, Values};
use crate::error::{Error, Result};
use crate::io::raw::RawGeometry;
use crate::io::text::{finite_normal, finite_point};

/// Reads the body: every element in header order, then checks nothing is left.
pub(crate) fn read_body<V: Values>(
    values: &mut V,
    header: &Header,
    path: &Path,
) -> Result<RawGeometry> {
    let layout = Layout::new(header, path)?;
    let num_vertices = header.elements[layout.vertex].count;
    let mut raw = RawGeometry::new();
    for (e, element) in header.elements.iter().enumerate() {
        let at = Reading {
            path,
            element,
            binary: V::BINARY,
        };
        if e == layout.vertex {
            read_vertices(values, &at, &layout, &mut raw)?;
        } else if let Some((_, list)) = layout.face.filter(|&(f, _)| f == e) {
            read_faces(values, &at, list, num_vertices, &mut raw)?;
        } else {
            skip_element(values, &at)?;
        }
    }
    if let Some(what) = values.leftover() {
        let msg = format!("{what}; the header's element counts do not match the data");
        return Err(Error::parse(path, values.location(0), msg));
    }
    Ok(raw)
}

/// The file and element being read, to word errors.
struct Reading<'a> {
    path: &'a Path,
    element: &'a Element,
    /// Binary data: structural errors then hint at a wrong count in the header.
    binary: bool,
}

impl Reading<'_> {
    /// Appended to structural errors: in binary data, reading out of step
    /// (after a wrong element count in the header) shows up as one of them.
    fn hint(&self) -> &'static str {
        if self.binary {
            " (in binary data this usually means an element count in the header is wrong)"
        } else {
            ""
        }
    }

    /// `error` with the hint appended to its message.
    fn hinted(&self, error: Error) -> Error {
        match error {
            Error::Parse {
                path,
                line,
                message,
            } => Error::Parse {
                path,
                line,
                message: message + self.hint(),
            },
            other => other,
        }
    }

    /// The error for a failed read of item `item`, property `property`.
    fn error(&self, fail: Fail, line: usize, item: usize, property: &str) -> Error {
        let name = &self.element.name;
        let message = match fail {
            Fail::End => {
                let count = self.element.count;
                let what = match name.as_str() {
                    "vertex" => "vertices".to_string(),
                    "face" => "faces".to_string(),
                    other => format!("`{other}` elements"),
                };
                format!(
                    "expected {count} {what}, but the file ends after {item}{}",
                    self.hint()
                )
            }
            Fail::Bad(token) => {
                format!("{name} {item}, property `{property}`: expected a number, found `{token}`")
            }
        };
        Error::parse(self.path, line, message)
    }

    /// The length of a list from its count value.
    fn list_len(&self, value: f64, line: usize, item: usize, property: &str) -> Result<usize> {
        if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
            Ok(value as usize)
        } else {
            let name = &self.element.name;
            let msg = format!(
                "{name} {item}, list `{property}`: bad length {value}{}",
                self.hint()
            );
            Err(Error::parse(self.path, line, msg))
        }
    }
}

/// Reads one scalar, turning a failure into an error that names the item.
fn scalar<V: Values>(
    values: &mut V,
    at: &Reading,
    ty: Scalar,
    item: usize,
    property: &str,
) -> Result<f64> {
    values
        .value(ty)
        .map_err(|f| at.error(f, values.location(item), item, property))
}

/// Reads past a list property of item `item`.
fn skip_list<V: Values>(
    values: &mut V,
    at: &Reading,
    (count, ty): (Scalar, Scalar),
    item: usize,
    property: &str,
) -> Result<()> {
    let len = scalar(values, at, count, item, property)?;
    let len = at.list_len(len, values.location(item), item, property)?;
    values
        .skip(ty, len)
        .map_err(|f| at.error(f, values.location(item), item, property))
}

/// Reads the `vertex` element: positions, and normals when the layout has them.
fn read_vertices<V: Values>(
    values: &mut V,
    at: &Reading,
    layout: &Layout,
    raw: &mut RawGeometry,
) -> Result<()> {
    let count = at.element.count;
    raw.positions.reserve(count.min(values.remaining()));
    let mut normals = Vec::new();
    if layout.has_normals {
        normals.reserve(count.min(values.remaining()));
    }
    let mut c = [0.0; 6];
    for item in 0..count {
        for (p, &slot) in at.element.properties.iter().zip(&layout.slots) {
            match (p.kind, slot) {
                (PropertyKind::Scalar(ty), Slot::Keep(k)) => {
                    c[k] = scalar(values, at, ty, item, &p.name)?;
                }
                (PropertyKind::Scalar(ty), Slot::Skip) => values
                    .skip(ty, 1)
                    .map_err(|f| at.error(f, values.location(item), item, &p.name))?,
                (PropertyKind::List { count, item: ty }, _) => {
                    skip_list(values, at, (count, ty), item, &p.name)?;
                }
            }
        }
        let line = values.location(item);
        raw.positions
            .push(finite_point(at.path, line, item, [c[0], c[1], c[2]])?);
        if layout.has_normals {
            normals.push(finite_normal(at.path, line, item, [c[3], c[4], c[5]])?);
        }
    }
    if layout.has_normals {
        raw.normals = Some(normals);
    }
    Ok(())
}

/// Reads the `face` element: property `list` holds the vertex indices.
fn read_faces<V: Values>(
    values: &mut V,
    at: &Reading,
    list: usize,
    num_vertices: usize,
    raw: &mut RawGeometry,
) -> Result<()> {
    let count = at.element.count;
    raw.face_offsets.reserve(count.min(values.remaining()));
    raw.face_vertices
        .reserve((3 * count).min(values.remaining()));
    for item in 0..count {
        for (i, p) in at.element.properties.iter().enumerate() {
            match p.kind {
                PropertyKind::List { count, item: ty } if i == list => {
                    let len = scalar(values, at, count, item, &p.name)?;
                    let len = at.list_len(len, values.location(item), item, &p.name)?;
                    for _ in 0..len {
                        let v = scalar(values, at, ty, item, &p.name)?;
                        if !(v >= 0.0 && v.fract() == 0.0 && v < num_vertices as f64) {
                            let msg = format!(
                                "face {item} refers to vertex {v}, but the file has \
                                 {num_vertices} vertices{}",
                                at.hint()
                            );
                            return Err(Error::parse(at.path, values.location(item), msg));
                        }
                        raw.face_vertices.push(v as u32);
                    }
                }
                PropertyKind::List { count, item: ty } => {
                    skip_list(values, at, (count, ty), item, &p.name)?;
                }
                PropertyKind::Scalar(ty) => values
                    .skip(ty, 1)
                    .map_err(|f| at.error(f, values.location(item), item, &p.name))?,
            }
        }
        raw.close_face(at.path, values.location(item), item)
            .map_err(|e| at.hinted(e))?;
    }
    Ok(())
}

/// Reads past an element the library does not use (`range_grid`, `material`, …):
/// at once when its items have a fixed binary size, item by item otherwise.
fn skip_element<V: Values>(values: &mut V, at: &Reading) -> Result<()> {
    let count = at.element.count;
    if at.element.properties.is_empty() {
        return Ok(());
    }
    if let (true, Some(size)) = (V::BINARY, at.element.fixed_size()) {
        let whole = count.checked_mul(size).filter(|&n| n <= values.remaining());
        return match whole {
            Some(n) => values
                .skip(Scalar::U8, n)
                .map_err(|f| at.error(f, 0, 0, "")),
            None => {
                let done = values.remaining() / size;
                Err(at.error(Fail::End, values.location(done), done, ""))
            }
        };
    }
    for item in 0..count {
        for p in &at.element.properties {
            match p.kind {
                PropertyKind::Scalar(ty) => values
                    .skip(ty, 1)
                    .map_err(|f| at.error(f, values.location(item), item, &p.name))?,
                PropertyKind::List { count, item: ty } => {
                    skip_list(values, at, (count, ty), item, &p.name)?;
                }
            }
        }
    }
    Ok(())
}

//! Which PLY element holds the vertices and which the faces, and which
//! vertex property goes where, decided from the header alone.

use std::path::Path;

use super::header::{Header, PropertyKind};
use crate::error::{Error, Result};

/// What to do with one vertex property: store it in slot 0..6 (`x y z nx ny nz`) or skip it.
#[derive(Clone, Copy)]
pub(super) enum Slot {
    /// Keep the value as coordinate `k` of `[x, y, z, nx, ny, nz]`.
    Keep(usize),
    /// Read past it.
    Skip,
}

/// Which elements carry the geometry, decided from the header alone.
pub(super) struct Layout {
    /// Index of the `vertex` element.
    pub vertex: usize,
    /// One slot per vertex property.
    pub slots: Vec<Slot>,
    /// Whether `nx ny nz` are all present.
    pub has_normals: bool,
    /// Index of the `face` element and of its index-list property.
    pub face: Option<(usize, usize)>,
}

impl Layout {
    /// Finds the `vertex` element (with scalar `x y z`) and the `face` element
    /// (with a `vertex_indices` or `vertex_index` list).
    pub fn new(header: &Header, path: &Path) -> Result<Layout> {
        let vertex = unique(header, "vertex", path)?
            .ok_or_else(|| Error::parse(path, 0, "the header declares no `vertex` element"))?;
        let element = &header.elements[vertex];
        if u32::try_from(element.count).is_err() {
            return Err(Error::parse(
                path,
                element.line,
                "more than 2^32 vertices in one file",
            ));
        }
        let mut slots = vec![Slot::Skip; element.properties.len()];
        let mut found = [false; 6];
        for (k, name) in ["x", "y", "z", "nx", "ny", "nz"].into_iter().enumerate() {
            match element.property(name) {
                Some((i, p)) if matches!(p.kind, PropertyKind::Scalar(_)) => {
                    slots[i] = Slot::Keep(k);
                    found[k] = true;
                }
                Some(_) if k < 3 => {
                    let msg =
                        format!("vertex property `{name}` must be a single number, not a list");
                    return Err(Error::parse(path, element.line, msg));
                }
                None if k < 3 => {
                    let msg = format!("the `vertex` element has no property `{name}`");
                    return Err(Error::parse(path, element.line, msg));
                }
                _ => {}
            }
        }
        let has_normals = found[3..].iter().all(|&f| f);
        if !has_normals {
            for slot in &mut slots {
                if matches!(slot, Slot::Keep(k) if *k >= 3) {
                    *slot = Slot::Skip;
                }
            }
        }
        let face = match unique(header, "face", path)? {
            None => None,
            Some(f) => {
                let element = &header.elements[f];
                let list = element
                    .property("vertex_indices")
                    .or_else(|| element.property("vertex_index"));
                match list {
                    Some((i, p)) if matches!(p.kind, PropertyKind::List { .. }) => Some((f, i)),
                    _ => {
                        let msg = "the `face` element has no `vertex_indices` list property";
                        return Err(Error::parse(path, element.line, msg));
                    }
                }
            }
        };
        Ok(Layout {
            vertex,
            slots,
            has_normals,
            face,
        })
    }
}

/// The index of the only element called `name`, if any.
fn unique(header: &Header, name: &str, path: &Path) -> Result<Option<usize>> {
    let mut found = header
        .elements
        .iter()
        .enumerate()
        .filter(|(_, e)| e.name == name);
    let first = found.next().map(|(i, _)| i);
    if let Some((_, second)) = found.next() {
        let msg = format!("a second `{name}` element; only one is supported");
        return Err(Error::parse(path, second.line, msg));
    }
    Ok(first)
}

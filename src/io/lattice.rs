//! The lattice JSON format (`.json`), read and written atomically.
//!
//! ```json
//! {
//!   "format": "subdyn-lattice",
//!   "version": 1,
//!   "vertices": [[0, 0, 0], [1, 0, 0], …],
//!   "faces": [[0, 3, 2, 1], …],
//!   "cells": [[0, 1, 2, 3, 4, 5], …],
//!   "hexahedra": [[0, 1, 2, 3, 4, 5, 6, 7], …],
//!   "polyhedra": [[[0, 2, 1], [0, 1, 3], …], …],
//!   "corners": [0, 5],
//!   "sharp_edges": [[0, 1], [1, 2]]
//! }
//! ```
//!
//! - `vertices` (required): control points `[x, y, z]`, indexed from 0.
//! - Cells, in one of two ways: `faces` (vertex loops, at least three
//!   vertices each) together with `cells` (each a list of face indices); or
//!   `hexahedra` (eight vertices in VTK order: 0–3 the bottom loop, 4–7 the
//!   top loop, `i + 4` above `i`) and/or `polyhedra` (each cell a list of
//!   vertex loops; faces shared by two cells are matched by their vertex
//!   sets). Any cell may have any number of faces of any size, as long as it
//!   is closed and bounds a ball; a face belongs to one or two cells; the
//!   cells must be connected through faces.
//! - `corners`, `sharp_edges` (optional): manual boundary tags. When either
//!   is present, the automatic marking is replaced (vertices that are not
//!   listed are not corners, edges that are not listed are not sharp); when
//!   both are absent, corners are the vertices in one cell and sharp edges
//!   the boundary edges in one cell (MacCracken & Joy 1996, §3).
//! - `format` and `version` are optional on input and always written.
//!
//! The writer emits `faces` and `cells`, and the tags only when they differ
//! from the automatic ones. Errors name the file and the line (for JSON
//! syntax and shape) or the element (for topology and geometry).

use std::collections::HashMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::lattice::{BoundaryTags, Lattice, LatticeTopology};
use crate::math::Point3;

use super::atomic::atomic_write;

/// The value of the `format` field.
pub const LATTICE_FORMAT: &str = "subdyn-lattice";

#[derive(Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct LatticeFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    format: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    version: Option<u32>,
    vertices: Vec<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    faces: Option<Vec<Vec<u32>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cells: Option<Vec<Vec<u32>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hexahedra: Option<Vec<[u32; 8]>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    polyhedra: Option<Vec<Vec<Vec<u32>>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    corners: Option<Vec<u32>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sharp_edges: Option<Vec<[u32; 2]>>,
}

/// Reads a lattice JSON file.
pub fn read_lattice(path: impl AsRef<Path>) -> Result<Lattice> {
    let path = path.as_ref();
    let bytes = super::read_input(path)?;
    lattice_from_json(&bytes, path)
}

/// Whether `path` names lattice JSON rather than another JSON file (a raw
/// volume's header, a sculpt script): a `.json` file holding an object with
/// `"format": "subdyn-lattice"`, or with a `"vertices"` list and no
/// `"format"`. An unreadable file is not a lattice (its reader then names
/// the problem).
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("lat.json");
/// std::fs::write(&path, r#"{"vertices": [], "hexahedra": []}"#).unwrap();
/// assert!(subdyn::io::is_lattice_file(&path));
/// std::fs::write(&path, r#"{"dims": [2, 2, 2], "dtype": "u8"}"#).unwrap();
/// assert!(!subdyn::io::is_lattice_file(&path));
/// ```
pub fn is_lattice_file(path: &Path) -> bool {
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if !json {
        return false;
    }
    let Ok(bytes) = super::read_input(path) else {
        return false;
    };
    match serde_json::from_slice::<serde_json::Value>(&bytes) {
        Ok(serde_json::Value::Object(map)) => match map.get("format") {
            Some(f) => f == LATTICE_FORMAT,
            None => map.get("vertices").is_some_and(serde_json::Value::is_array),
        },
        _ => false,
    }
}

/// Parses lattice JSON; `path` only names the source in errors.
pub fn lattice_from_json(bytes: &[u8], path: &Path) -> Result<Lattice> {
    let file: LatticeFile =
        serde_json::from_slice(bytes).map_err(|e| Error::parse(path, e.line(), e.to_string()))?;
    let name = path.display();
    if let Some(f) = &file.format
        && f != LATTICE_FORMAT
    {
        return Err(Error::parse(
            path,
            0,
            format!("\"format\" is {f:?}, expected {LATTICE_FORMAT:?}"),
        ));
    }
    let positions: Vec<Point3> = file
        .vertices
        .iter()
        .map(|p| Point3::new(p[0], p[1], p[2]))
        .collect();
    let in_file = |e: Error| match e {
        Error::Topology(m) => Error::Topology(format!("{name}: {m}")),
        Error::Input(m) => Error::with_kind(m.kind(), format!("{name}: {m}")),
        other => other,
    };
    let topo = match (&file.faces, &file.cells, &file.hexahedra, &file.polyhedra) {
        (Some(faces), Some(cells), None, None) => {
            LatticeTopology::new(positions.len(), faces, cells).map_err(in_file)?
        }
        (None, None, hex, poly) if hex.is_some() || poly.is_some() => {
            let mut cells: Vec<Vec<Vec<u32>>> = Vec::new();
            for h in hex.iter().flatten() {
                cells.push(
                    crate::lattice::HEX_FACES
                        .iter()
                        .map(|f| f.iter().map(|&i| h[i]).collect())
                        .collect(),
                );
            }
            cells.extend(poly.iter().flatten().cloned());
            LatticeTopology::from_polyhedra(positions.len(), &cells).map_err(in_file)?
        }
        _ => {
            return Err(Error::parse(
                path,
                0,
                "expected either \"faces\" and \"cells\", or \"hexahedra\" and/or \"polyhedra\"",
            ));
        }
    };
    let tags = if file.corners.is_none() && file.sharp_edges.is_none() {
        BoundaryTags::automatic(&topo)
    } else {
        manual_tags(&topo, &file).map_err(in_file)?
    };
    Lattice::with_tags(positions, topo, tags).map_err(in_file)
}

fn manual_tags(topo: &LatticeTopology, file: &LatticeFile) -> Result<BoundaryTags> {
    let mut corners = vec![false; topo.num_vertices];
    for &v in file.corners.iter().flatten() {
        *corners
            .get_mut(v as usize)
            .ok_or_else(|| Error::Topology(format!("corner {v}: no such vertex")))? = true;
    }
    let ids: HashMap<[u32; 2], usize> = topo
        .edges
        .iter()
        .enumerate()
        .map(|(i, &e)| (e, i))
        .collect();
    let mut sharp_edges = vec![false; topo.num_edges()];
    for &[a, b] in file.sharp_edges.iter().flatten() {
        let e = ids
            .get(&[a.min(b), a.max(b)])
            .ok_or_else(|| Error::Topology(format!("sharp edge {a}-{b}: no such edge")))?;
        sharp_edges[*e] = true;
    }
    Ok(BoundaryTags {
        corners,
        sharp_edges,
    })
}

/// The lattice as JSON text (faces and cells; tags only when not automatic).
pub fn lattice_to_json(lattice: &Lattice) -> String {
    let t = &lattice.topology;
    let manual = lattice.tags != BoundaryTags::automatic(t);
    let file = LatticeFile {
        format: Some(LATTICE_FORMAT.into()),
        version: Some(1),
        vertices: lattice.positions.iter().map(|p| [p.x, p.y, p.z]).collect(),
        faces: Some(
            (0..t.num_faces())
                .map(|f| t.faces.row(f).to_vec())
                .collect(),
        ),
        cells: Some(
            (0..t.num_cells())
                .map(|c| t.cells.row(c).to_vec())
                .collect(),
        ),
        hexahedra: None,
        polyhedra: None,
        corners: manual.then(|| {
            (0..t.num_vertices as u32)
                .filter(|&v| lattice.tags.corners[v as usize])
                .collect()
        }),
        sharp_edges: manual.then(|| {
            t.edges
                .iter()
                .zip(&lattice.tags.sharp_edges)
                .filter(|(_, s)| **s)
                .map(|(e, _)| *e)
                .collect()
        }),
    };
    // One vertex, face or cell per line keeps the files diff-friendly.
    let mut out = String::from("{\n");
    let line = |key: &str, v: String, last: bool| {
        format!("  \"{key}\": {v}{}\n", if last { "" } else { "," })
    };
    let list = |items: Vec<String>| format!("[\n    {}\n  ]", items.join(",\n    "));
    out += &line("format", js(&file.format), false);
    out += &line("version", js(&file.version), false);
    out += &line(
        "vertices",
        list(file.vertices.iter().map(js).collect()),
        false,
    );
    out += &line(
        "faces",
        list(file.faces.iter().flatten().map(js).collect()),
        false,
    );
    let has_tags = file.corners.is_some();
    out += &line(
        "cells",
        list(file.cells.iter().flatten().map(js).collect()),
        !has_tags,
    );
    if has_tags {
        out += &line("corners", js(&file.corners), false);
        out += &line("sharp_edges", js(&file.sharp_edges), true);
    }
    out += "}\n";
    out
}

/// One value as compact JSON (serialising plain numbers and lists cannot fail).
fn js<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default()
}

/// Writes a lattice JSON file atomically.
pub fn write_lattice(path: impl AsRef<Path>, lattice: &Lattice) -> Result<()> {
    let text = lattice_to_json(lattice);
    atomic_write(path.as_ref(), |w| w.write_all(text.as_bytes()))
}

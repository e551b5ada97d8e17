//! `subdyn info LAT.json [--json]`: the counts of a lattice JSON file (the
//! file `subdyn lattice` writes): control points, cells, faces, edges and
//! boundary tags.

use std::fmt::Write as _;
use std::path::Path;

use serde_json::json;

use subdyn::io::read_lattice;
use subdyn::lattice::Lattice;

use super::common::{about_file, bbox_json, print_stdout, thousands};
use super::info::bbox_text;

/// Prints what `read_lattice` finds in `path`.
pub fn run(path: &Path, as_json: bool) -> anyhow::Result<()> {
    let lattice = read_lattice(path).map_err(|e| about_file(e, path))?;
    let c = LatticeCounts::of(&lattice);
    let text = if as_json {
        format!(
            "{}\n",
            json!({
                "file": path.display().to_string(),
                "kind": "lattice",
                "control_points": c.control_points,
                "cells": c.cells,
                "hexahedra": c.hexahedra,
                "faces": c.faces,
                "boundary_faces": c.boundary_faces,
                "edges": c.edges,
                "corners": c.corners,
                "sharp_edges": c.sharp_edges,
                "bbox": bbox_json(&lattice.positions),
            })
        )
    } else {
        let mut s = String::new();
        let _ = writeln!(s, "file:                 {} (lattice JSON)", path.display());
        let _ = writeln!(s, "control points:       {}", thousands(c.control_points));
        let _ = writeln!(
            s,
            "cells:                {} ({} hexahedra)",
            thousands(c.cells),
            thousands(c.hexahedra)
        );
        let _ = writeln!(
            s,
            "faces:                {} ({} on the boundary)",
            thousands(c.faces),
            thousands(c.boundary_faces)
        );
        let _ = writeln!(s, "edges:                {}", thousands(c.edges));
        let _ = writeln!(s, "corners:              {}", thousands(c.corners));
        let _ = writeln!(s, "sharp edges:          {}", thousands(c.sharp_edges));
        s + &bbox_text(&lattice.positions)
            + "(control point numbers: subdyn lattice --list-vertices, or subdyn render LAT.json --label-vertices)\n"
    };
    print_stdout(&text)
}

/// What `info` counts in a lattice.
struct LatticeCounts {
    control_points: usize,
    cells: usize,
    hexahedra: usize,
    faces: usize,
    boundary_faces: usize,
    edges: usize,
    corners: usize,
    sharp_edges: usize,
}

impl LatticeCounts {
    fn of(lattice: &Lattice) -> Self {
        let t = &lattice.topology;
        let hexahedra = (0..t.num_cells())
            .filter(|&c| {
                t.cells.row(c).len() == 6
                    && t.cell_vertices.row(c).len() == 8
                    && t.cells
                        .row(c)
                        .iter()
                        .all(|&f| t.faces.row(f as usize).len() == 4)
            })
            .count();
        let count = |flags: &[bool]| flags.iter().filter(|&&b| b).count();
        LatticeCounts {
            control_points: lattice.num_vertices(),
            cells: t.num_cells(),
            hexahedra,
            faces: t.num_faces(),
            boundary_faces: t.boundary_faces().len(),
            edges: t.num_edges(),
            corners: count(&lattice.tags.corners),
            sharp_edges: count(&lattice.tags.sharp_edges),
        }
    }
}

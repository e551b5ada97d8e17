//! `subdyn lattice MODEL -o LAT.json [--box aabb|obb] [--octree-levels K]
//! [--margin F] [--no-cull] [--shrink OFFSET] [--refine-cells IDS]`: an
//! automatic lattice around a model (multiresolution-lattice FFD paper:
//! bounding box, octree levels, culling, shrink lattices, local refinement).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use serde_json::json;

use subdyn::io::{read_mesh, write_lattice};
use subdyn::lattice::{
    BoxKind, BoxLatticeParams, box_lattice, locally_refined, shrunk_box_lattice,
};

use super::common::{Written, about_file, check_output_dir, thousands, write_report};

/// Box orientation on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BoxArg {
    /// Axis-aligned bounding box.
    Aabb,
    /// Oriented bounding box along the principal axes (PCA).
    Obb,
}

/// Arguments of `subdyn lattice`.
#[derive(Debug, Args)]
pub struct LatticeArgs {
    /// The model (.obj, .ply, .off, .xyz): its vertices decide the box and the culling.
    #[arg(value_name = "MODEL")]
    pub model: PathBuf,
    /// Output lattice JSON.
    #[arg(short, long, value_name = "LAT.json")]
    pub output: PathBuf,
    /// Box orientation.
    #[arg(long = "box", value_enum, default_value_t = BoxArg::Aabb)]
    pub kind: BoxArg,
    /// Octree levels K: 2^K cells per axis before culling (0 to 7).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub octree_levels: usize,
    /// Margin on every side, as a fraction of the model's diagonal.
    #[arg(long, value_name = "F", default_value_t = 0.05)]
    pub margin: f64,
    /// Keep the cells that hold no model vertex.
    #[arg(long)]
    pub no_cull: bool,
    /// Shrink lattice: move boundary control points along their axis
    /// towards the model, keeping this offset (a fraction of the model's
    /// diagonal) from the farthest vertex they control.
    #[arg(long, value_name = "OFFSET")]
    pub shrink: Option<f64>,
    /// Refine these cells by the octree rules (comma-separated cell indices
    /// of the lattice before refinement); their neighbours become
    /// non-hexahedral cells.
    #[arg(long, value_name = "IDS", value_delimiter = ',')]
    pub refine_cells: Vec<usize>,
    /// Write a JSON report.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Also print every control point: its number (the `"vertex"` of
    /// `subdyn ffd --moves`) and its position. `subdyn render LAT.json
    /// --label-vertices` shows the numbers in a picture.
    #[arg(long)]
    pub list_vertices: bool,
}

/// `vertex x y z` lines, one per control point, numbered from 0.
fn vertex_table(positions: &[subdyn::math::Point3]) -> String {
    let mut s = format!("{:>6}  {:>12}  {:>12}  {:>12}\n", "vertex", "x", "y", "z");
    for (i, p) in positions.iter().enumerate() {
        s += &format!("{i:>6}  {:>12.6}  {:>12.6}  {:>12.6}\n", p.x, p.y, p.z);
    }
    s
}

/// Runs `subdyn lattice`.
pub fn run(args: &LatticeArgs) -> anyhow::Result<()> {
    if args.output.extension().and_then(|e| e.to_str()) != Some("json") {
        anyhow::bail!(
            "{}: the lattice is written as JSON; use a .json name",
            args.output.display()
        );
    }
    check_output_dir(&args.output)?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    let mesh = read_mesh(&args.model).map_err(|e| about_file(e, &args.model))?;
    let params = BoxLatticeParams {
        kind: match args.kind {
            BoxArg::Aabb => BoxKind::Aabb,
            BoxArg::Obb => BoxKind::Obb,
        },
        margin: args.margin,
        octree_levels: args.octree_levels,
        cull: !args.no_cull,
        ..Default::default()
    };
    let (lat, shrink) = match args.shrink {
        Some(offset) => {
            let (lat, r) = shrunk_box_lattice(&mesh.positions, &params, offset)
                .map_err(|e| about_file(e, &args.model))?;
            (lat, Some(r))
        }
        None => (
            box_lattice(&mesh.positions, &params).map_err(|e| about_file(e, &args.model))?,
            None,
        ),
    };
    let (lat, local) = if args.refine_cells.is_empty() {
        (lat, None)
    } else {
        let (lat, r) = locally_refined(&lat, &args.refine_cells)
            .map_err(|e| anyhow::anyhow!("--refine-cells: {e}"))?;
        (lat, Some(r))
    };
    write_lattice(&args.output, &lat).map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(&args.output, "lattice");
    if let Some(report) = &args.report {
        write_report(
            report,
            &json!({
                "command": "lattice",
                "model": args.model.display().to_string(),
                "output": args.output.display().to_string(),
                "vertices": lat.num_vertices(),
                "cells": lat.topology.num_cells(),
                "octree_levels": args.octree_levels,
                "cells_before_culling": 1usize << (3 * args.octree_levels),
                "shrink": shrink,
                "local_refinement": local,
            }),
        )?;
        written.add(report, "report");
    }
    let mut extra = String::new();
    if let Some(r) = &shrink {
        extra += &format!(
            "; shrunk: {} boundary points moved (up to {:.3} of the diagonal)",
            r.moved, r.max_move
        );
    }
    if let Some(r) = &local {
        extra += &format!(
            "; {} cells refined locally, {} non-hexahedral cells",
            r.refined, r.non_hexahedral
        );
    }
    if args.list_vertices {
        extra += &format!("\n{}", vertex_table(&lat.positions).trim_end());
    }
    written.print_after(&format!(
        "lattice around {} ({} vertices): {} control points, {} cells (of {} before culling){extra}\n",
        args.model.display(),
        thousands(mesh.num_vertices()),
        thousands(lat.num_vertices()),
        thousands(lat.topology.num_cells()),
        thousands(1usize << (3 * args.octree_levels)),
    ))
}

//! `subdyn ffd MODEL --lattice LAT.json (--deformed LAT2.json | --moves MOVES.json)
//! [--levels N] -o OUT.obj [--report R.json]`: free-form deformation of a
//! mesh with a Catmull-Clark volume lattice (MacCracken & Joy 1996).
//!
//! MOVES.json lists control-point moves:
//! `{"moves": [{"vertex": 3, "offset": [0, 0, 0.5]}, {"vertex": 7, "position": [1, 2, 3]}]}`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde::Deserialize;
use serde_json::json;

use subdyn::ffd::{Ffd, FfdParams};
use subdyn::io::{read_lattice, write_mesh};
use subdyn::lattice::MAX_LATTICE_LEVELS;
use subdyn::math::{Point3, Vector3};

use super::common::{
    Written, about_file, check_mesh_output, check_output_dir, seconds, thousands, write_report,
};
use super::options::read_polygon_mesh;
use super::progress::Progress;

/// Arguments of `subdyn ffd`.
#[derive(Debug, Args)]
#[command(after_help = MOVES_HELP)]
pub struct FfdArgs {
    /// The model to deform (.obj, .ply, .off).
    #[arg(value_name = "MODEL")]
    pub model: PathBuf,
    /// The lattice in its rest position (lattice JSON).
    #[arg(long, value_name = "LAT.json")]
    pub lattice: PathBuf,
    /// The same lattice with moved control points.
    #[arg(
        long,
        value_name = "LAT2.json",
        conflicts_with = "moves",
        required_unless_present = "moves"
    )]
    pub deformed: Option<PathBuf>,
    /// Control-point moves (JSON: {"moves": [{"vertex": 3, "offset": [0, 0, 0.5]}, …]}; format below).
    #[arg(long, value_name = "MOVES.json")]
    pub moves: Option<PathBuf>,
    /// Refinement levels of the lattice (1 to 6).
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub levels: usize,
    /// Output mesh; the format follows the extension.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Write a JSON report (embedded / outside counts, timings).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// No progress display and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The `--moves` format, shown by `subdyn ffd --help`.
const MOVES_HELP: &str = "MOVES.json lists control points of the lattice to move:
  {\"moves\": [{\"vertex\": 3, \"offset\": [0, 0, 0.5]}, {\"vertex\": 7, \"position\": [1, 2, 3]}]}
Each move names a control point by its number (its place in the lattice file's \"vertices\", from 0)
and gives exactly one of \"offset\" (added to its rest position) or \"position\" (where it goes).
`subdyn lattice MODEL -o LAT.json --list-vertices` prints the numbers and positions;
`subdyn render LAT.json -o LAT.png --label-vertices` draws them.";

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MovesFile {
    moves: Vec<Move>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Move {
    vertex: usize,
    #[serde(default)]
    offset: Option<[f64; 3]>,
    #[serde(default)]
    position: Option<[f64; 3]>,
}

/// The moved control points from a moves file.
fn read_moves(path: &Path, rest: &[Point3]) -> anyhow::Result<Vec<Point3>> {
    let bytes = subdyn::io::read_input(path)?;
    let file: MovesFile = serde_json::from_slice(&bytes)
        .map_err(|e| subdyn::Error::parse(path, e.line(), e.to_string()))?;
    let mut out = rest.to_vec();
    for (i, m) in file.moves.iter().enumerate() {
        let name = path.display();
        let q = out.get_mut(m.vertex).ok_or_else(|| {
            anyhow::anyhow!(
                "{name}: move {i}: vertex {} does not exist (the lattice has {} control points)",
                m.vertex,
                rest.len()
            )
        })?;
        match (m.offset, m.position) {
            (Some(d), None) => *q += Vector3::new(d[0], d[1], d[2]),
            (None, Some(p)) => *q = Point3::new(p[0], p[1], p[2]),
            _ => anyhow::bail!("{name}: move {i}: give exactly one of \"offset\" and \"position\""),
        }
        if !q.coords.iter().all(|x| x.is_finite()) {
            anyhow::bail!(
                "{name}: move {i}: vertex {} would move to a non-finite position",
                m.vertex
            );
        }
    }
    Ok(out)
}

/// Says that the lattice is refined `levels` times and the model embedded;
/// the parameters for it.
pub fn embedding_stage(progress: &Progress, levels: usize) -> FfdParams {
    progress.stage(format!("refining the lattice {levels} times and embedding"));
    FfdParams {
        levels,
        ..Default::default()
    }
}

/// Runs `subdyn ffd`.
pub fn run(args: &FfdArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    check_mesh_output(&args.output)?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if args.levels == 0 || args.levels > MAX_LATTICE_LEVELS {
        anyhow::bail!(
            "--levels {} is out of range: expected 1 to {MAX_LATTICE_LEVELS}",
            args.levels
        );
    }
    let progress = Progress::new(args.quiet);
    progress.stage("reading the model and the lattice");
    let mesh = read_polygon_mesh(&args.model, args.quiet)?;
    let lattice = read_lattice(&args.lattice).map_err(|e| about_file(e, &args.lattice))?;
    let moved = match (&args.deformed, &args.moves) {
        (Some(path), _) => {
            let d = read_lattice(path).map_err(|e| about_file(e, path))?;
            if d.topology != lattice.topology {
                anyhow::bail!(
                    "{}: not the same lattice as {} ({} vertices, {} cells against {} and {})",
                    path.display(),
                    args.lattice.display(),
                    d.num_vertices(),
                    d.topology.num_cells(),
                    lattice.num_vertices(),
                    lattice.topology.num_cells()
                );
            }
            d.positions
        }
        (None, Some(path)) => read_moves(path, &lattice.positions)?,
        (None, None) => anyhow::bail!("give --deformed or --moves"),
    };
    let params = embedding_stage(&progress, args.levels);
    let ffd = Ffd::new(&lattice, &mesh.positions, &params)?;
    let t = Instant::now();
    // An error here is about the moved lattice, not the output.
    let moves_source = (args.moves.as_ref())
        .or(args.deformed.as_ref())
        .unwrap_or(&args.lattice);
    let positions = ffd
        .deform(&moved)
        .map_err(|e| about_file(e, moves_source))?;
    let deform_s = seconds(t);
    let mut out = mesh.clone();
    out.positions = positions;
    progress.stage(format!("writing {}", args.output.display()));
    write_mesh(&args.output, &out, None).map_err(|e| about_file(e, &args.output))?;
    drop(progress);
    let mut written = Written::new();
    written.add(&args.output, "deformed mesh");
    let r = &ffd.report;
    if r.outside > 0 && !args.quiet {
        super::common::warn(
            args.quiet,
            &format!(
                "{} of {} vertices lie outside the lattice and were not moved",
                thousands(r.outside),
                thousands(r.points)
            ),
        );
    }
    if let Some(report) = &args.report {
        let value = json!({
            "command": "ffd",
            "model": args.model.display().to_string(),
            "lattice": args.lattice.display().to_string(),
            "output": args.output.display().to_string(),
            "ffd": r,
            "lattice_vertices": lattice.num_vertices(),
            "lattice_cells": lattice.topology.num_cells(),
            "timings_s": {"refine": r.refine_s, "embed": r.embed_s, "deform": deform_s, "total": seconds(start)},
        });
        write_report(report, &value)?;
        written.add(report, "report");
    }
    written.print_after(&format!(
        "deformed {} of {} vertices of {} with {} ({} cells, {} levels → {} cells); {} outside\n",
        thousands(r.embedded),
        thousands(r.points),
        args.model.display(),
        args.lattice.display(),
        lattice.topology.num_cells(),
        args.levels,
        thousands(r.level_cells),
        thousands(r.outside),
    ))
}

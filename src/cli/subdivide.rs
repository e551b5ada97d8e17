//! `subdyn subdivide [IN] -o OUT --levels N`: uniform Catmull-Clark refinement.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde_json::json;

use subdyn::io::write_mesh;
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{check_uniform_size, uniform_positions};

use super::common::{
    Written, about_file, bbox_json, check_mesh_output, check_output_dir, seconds, thousands, timed,
    write_report,
};
use super::options::{RefineArgs, read_polygon_mesh};
use super::progress::Progress;
use super::subdivide_scheme::{Scheme, refine_other};

pub use subdyn::subdivision::{MAX_FACES, MAX_LEVELS};

/// Arguments of `subdyn subdivide`.
#[derive(Debug, Args)]
pub struct SubdivideArgs {
    /// Input mesh (.obj, .ply, .off); without it, the embedded unit cube is refined.
    #[arg(value_name = "IN")]
    pub input: Option<PathBuf>,
    /// Output mesh; the format follows the extension.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Number of uniform refinement levels (0 to 8).
    #[arg(short, long, default_value_t = 2)]
    pub levels: usize,
    /// Move every output vertex to its position on the limit surface
    /// (Catmull-Clark only); the faces are then written as triangles (see
    /// --quads).
    #[arg(long)]
    pub limit: bool,
    /// With --limit, keep the quads (default: triangles, each quad split
    /// along the diagonal whose two triangles face the same way best).
    #[arg(long, requires = "limit")]
    pub quads: bool,
    /// Subdivision scheme.
    #[arg(long, value_enum, default_value_t = Scheme::CatmullClark)]
    pub scheme: Scheme,
    /// Knot intervals for `--scheme non-uniform`: lines `i j d` (edge between
    /// vertices i and j gets interval d ≥ 0; unlisted edges get 1).
    #[arg(long, value_name = "FILE")]
    pub knots: Option<PathBuf>,
    #[command(flatten)]
    pub refine: RefineArgs,
    /// Write a JSON report (counts per level, timings, bounding box).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// No progress display and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `subdyn subdivide`.
pub fn run(args: &SubdivideArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    check_mesh_output(&args.output)?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if args.levels > MAX_LEVELS {
        anyhow::bail!(
            "--levels {} is too many: each level multiplies the faces by 4; at most {MAX_LEVELS} levels are allowed",
            args.levels
        );
    }
    let progress = Progress::new(args.quiet);
    progress.stage("reading the mesh");
    let ((mesh, input_name), read_s) = timed(|| load(args.input.as_deref(), args.quiet));
    let input_label = match &args.input {
        Some(path) => path.display().to_string(),
        None => "embedded:cube".to_string(),
    };
    let mesh = mesh?;
    check_uniform_size(&mesh, args.levels, args.limit)
        .map_err(|e| about_file(e, Path::new(&input_name)))?;
    if args.scheme != Scheme::CatmullClark {
        return run_other(args, &mesh, &input_name);
    }

    progress.stage("building the topology");
    let (refiner, topology_s) = timed(|| args.refine.refiner(&mesh, Path::new(&input_name)));
    let refiner = refiner?;
    progress.stage(format!("refining to level {}", args.levels));
    let (hierarchy, refine_s) = timed(|| refiner.refine_uniform(args.levels));
    let hierarchy = hierarchy?;

    progress.stage("computing the positions");
    let (positions, positions_s) =
        timed(|| uniform_positions(&hierarchy, &mesh.positions, args.levels, args.limit));
    let positions = positions?;
    let bbox = bbox_json(&positions);
    let out = hierarchy.mesh(args.levels, positions);
    let out = if args.limit && !args.quads {
        subdyn::mesh::split_quads(&out)
    } else {
        out
    };

    progress.stage(format!("writing {}", args.output.display()));
    let (written, write_s) = timed(|| write_mesh(&args.output, &out, None));
    written.map_err(|e| about_file(e, &args.output))?;
    drop(progress);
    let mut written = Written::new();
    written.add(&args.output, "subdivided mesh");

    let summary = format!(
        "{}{} to level {}{}: {} vertices, {} faces\n",
        if args.input.is_none() {
            "no INPUT given: subdivided "
        } else {
            "subdivided "
        },
        input_name,
        args.levels,
        if args.limit {
            " (vertices at their limit positions)"
        } else {
            ""
        },
        thousands(out.num_vertices()),
        thousands(out.num_faces()),
    );
    if let Some(report) = &args.report {
        let counts: Vec<_> = hierarchy
            .levels
            .iter()
            .enumerate()
            .map(|(k, l)| json!({"level": k, "vertices": l.num_vertices, "faces": l.num_faces(), "edges": l.num_edges()}))
            .collect();
        let value = json!({
            "command": "subdivide",
            "input": input_label,
            "output": args.output.display().to_string(),
            "levels": args.levels,
            "boundary": refiner.options.boundary.name(),
            "creases": refiner.options.creases.len(),
            "corners": refiner.options.corners.len(),
            "holes": refiner.options.holes.len(),
            "limit": args.limit,
            "counts": counts,
            "timings_s": {
                "read": read_s,
                "topology": topology_s,
                "refine": refine_s,
                "positions": positions_s,
                "write": write_s,
                "total": seconds(start),
            },
            "input_bbox": bbox_json(&mesh.positions),
            "bbox": bbox,
        });
        write_report(report, &value)?;
        written.add(report, "report");
    }
    written.print_after(&summary)
}

/// `subdivide` with Doo-Sabin or non-uniform Catmull-Clark.
fn run_other(args: &SubdivideArgs, mesh: &PolyMesh, input_name: &str) -> anyhow::Result<()> {
    if args.limit {
        anyhow::bail!("--limit is only available with --scheme catmull-clark");
    }
    let out = refine_other(mesh, args.scheme, args.levels, args.knots.as_ref())
        .map_err(|e| e.context(input_name.to_string()))?;
    write_mesh(&args.output, &out, None).map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(&args.output, "subdivided mesh");
    if let Some(report) = &args.report {
        let value = json!({
            "command": "subdivide",
            "scheme": args.scheme.name(),
            "input": input_name,
            "output": args.output.display().to_string(),
            "levels": args.levels,
            "vertices": out.num_vertices(),
            "faces": out.num_faces(),
            "bbox": bbox_json(&out.positions),
        });
        write_report(report, &value)?;
        written.add(report, "report");
    }
    written.print_after(&format!(
        "subdivided {input_name} with {} to level {}: {} vertices, {} faces\n",
        args.scheme.name(),
        args.levels,
        thousands(out.num_vertices()),
        thousands(out.num_faces()),
    ))
}

/// The input mesh and its name for messages: the file, or the embedded cube.
fn load(input: Option<&Path>, quiet: bool) -> (anyhow::Result<PolyMesh>, String) {
    match input {
        Some(path) => (read_polygon_mesh(path, quiet), path.display().to_string()),
        None => (
            Ok(subdyn::examples::cube()),
            "the embedded unit cube (8 vertices, 6 quads)".to_string(),
        ),
    }
}

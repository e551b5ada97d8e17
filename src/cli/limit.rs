//! `subdyn limit IN -o OUT --tess K`: tessellate the limit surface.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde_json::json;

use subdyn::io::write_mesh;
use subdyn::limit::tessellate;

use super::common::{
    Written, about_file, bbox_json, check_mesh_output, check_output_dir, seconds, thousands, timed,
    write_report,
};
use super::options::{LimitFacesArgs, RefineArgs, read_polygon_mesh};
use super::progress::Progress;
use super::subdivide::MAX_FACES;

/// Largest `--tess` accepted.
pub const MAX_TESS: usize = 256;

/// Arguments of `subdyn limit`.
#[derive(Debug, Args)]
pub struct LimitArgs {
    /// Input control mesh (.obj, .ply, .off).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output mesh; the format follows the extension.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Samples per quad edge: each quad (each quad sub-face of an n-gon)
    /// becomes a K×K grid of quads (2 K² triangles) whose vertices lie on the
    /// limit surface.
    #[arg(short = 'k', long = "tess", value_name = "K", default_value_t = 4)]
    pub tess: usize,
    /// Also write the limit-surface unit normal of every output vertex.
    #[arg(long)]
    pub normals: bool,
    #[command(flatten)]
    pub refine: RefineArgs,
    #[command(flatten)]
    pub faces: LimitFacesArgs,
    /// Write a JSON report (counts, timings, bounding box).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// No progress display and no warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `subdyn limit`.
pub fn run(args: &LimitArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    check_mesh_output(&args.output)?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if args.tess == 0 || args.tess > MAX_TESS {
        anyhow::bail!(
            "--tess {} is out of range: expected 1 to {MAX_TESS}",
            args.tess
        );
    }
    let progress = Progress::new(args.quiet);
    let name = args.input.display().to_string();
    progress.stage("reading the mesh");
    let (mesh, read_s) = timed(|| read_polygon_mesh(&args.input, args.quiet));
    let mesh = mesh?;
    // Quads (and quad sub-faces of n-gons) times K² faces each.
    let quads = mesh
        .faces()
        .map(|f| if f.len() == 4 { 1 } else { f.len() })
        .sum::<usize>();
    let faces = quads as f64 * (args.tess * args.tess) as f64;
    if faces > MAX_FACES as f64 {
        anyhow::bail!(
            "{name}: --tess {} would make about {} faces (at most {} allowed); use a smaller K",
            args.tess,
            thousands(faces as usize),
            thousands(MAX_FACES)
        );
    }

    progress.stage("building the topology");
    let (refiner, topology_s) = timed(|| args.refine.refiner(&mesh, &args.input));
    let refiner = refiner?;
    progress.stage(format!(
        "tessellating the limit surface ({0}×{0} per quad)",
        args.tess
    ));
    let (tess, tess_s) = timed(|| tessellate(&refiner, &mesh.positions, args.tess));
    let (out, normals) = tess.map_err(|e| about_file(e, &args.input))?;
    let out = args.faces.mesh(&out);

    progress.stage(format!("writing {}", args.output.display()));
    let normals = args.normals.then_some(normals.as_slice());
    let (written, write_s) = timed(|| write_mesh(&args.output, &out, normals));
    written.map_err(|e| about_file(e, &args.output))?;
    drop(progress);
    let mut written = Written::new();
    written.add(&args.output, "limit surface");

    if let Some(report) = &args.report {
        let value = json!({
            "command": "limit",
            "input": name,
            "output": args.output.display().to_string(),
            "tess": args.tess,
            "normals": args.normals,
            "quads": args.faces.quads,
            "boundary": refiner.options.boundary.name(),
            "creases": refiner.options.creases.len(),
            "corners": refiner.options.corners.len(),
            "holes": refiner.options.holes.len(),
            "control": {"vertices": mesh.num_vertices(), "faces": mesh.num_faces()},
            "tessellation": {"vertices": out.num_vertices(), "faces": out.num_faces()},
            "timings_s": {
                "read": read_s,
                "topology": topology_s,
                "tessellate": tess_s,
                "write": write_s,
                "total": seconds(start),
            },
            "bbox": bbox_json(&out.positions),
        });
        write_report(report, &value)?;
        written.add(report, "report");
    }
    written.print_after(&format!(
        "tessellated the limit surface of {name} ({0}×{0} per quad): {1} vertices, {2} faces{3}\n",
        args.tess,
        thousands(out.num_vertices()),
        thousands(out.num_faces()),
        if args.normals { " with normals" } else { "" },
    ))
}

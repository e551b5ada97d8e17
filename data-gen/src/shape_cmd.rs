//! `data-gen shape NAME -o OUT`: a closed reference mesh and its sidecar.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use serde_json::json;

use crate::shapes::ShapeKind;
use crate::sidecar::{GENERATOR, create_parent, path_from_sidecar, sidecar_path, write_json};
use crate::truth::{ShapeOptions, TruthSource, ground_truth};

/// Options of `data-gen shape`.
#[derive(Args, Debug)]
pub struct ShapeArgs {
    /// The shape to generate.
    #[arg(value_enum, required_unless_present = "from", conflicts_with = "from")]
    pub name: Option<ShapeKind>,
    /// Instead of a built-in shape, read this mesh (OBJ, PLY, OFF; optionally
    /// .gz), check it and write it in OUT's format with a sidecar.
    #[arg(long, value_name = "FILE")]
    pub from: Option<PathBuf>,
    /// Output mesh; the format follows the extension (.obj, .ply, .off, optionally .gz).
    /// The sidecar goes to OUT with the extension replaced by .json.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Mesh resolution; its meaning and default depend on the shape (sphere,
    /// ellipsoid: quads per cube-face side, 64; torus: segments around the
    /// axis, 128; bulb: profile steps and segments, 128; genus2, anvil:
    /// polygonisation cells along the longest side, 110).
    #[arg(long, value_name = "R")]
    pub resolution: Option<usize>,
    #[command(flatten)]
    pub shape: ShapeOptions,
}

/// Runs `data-gen shape`.
pub fn run(args: &ShapeArgs) -> Result<()> {
    subdyn::io::MeshFormat::from_path(&args.output)?;
    let source = match (&args.name, &args.from) {
        (Some(kind), None) => TruthSource::Shape(*kind, args.shape.params(args.resolution)),
        (None, Some(path)) => TruthSource::File(path.clone()),
        _ => bail!("give a shape name or --from FILE"),
    };
    let truth = ground_truth(&source)?;
    let sidecar = sidecar_path(&args.output);
    create_parent(&args.output)?;
    subdyn::io::write_mesh(&args.output, &truth.mesh, None)?;
    let record = json!({
        "generator": GENERATOR,
        "kind": "shape",
        "mesh": path_from_sidecar(&args.output, &sidecar),
        "ground_truth": truth.info,
    });
    write_json(&sidecar, &record)?;
    let t = &record["ground_truth"]["topology"];
    println!(
        "{}: {} {} vertices, {} faces, V-E+F = {}, genus {}; sidecar {}",
        args.output.display(),
        truth.name,
        t["vertices"],
        t["faces"],
        t["euler_characteristic"],
        t["genus"],
        sidecar.display()
    );
    Ok(())
}

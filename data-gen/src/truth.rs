//! `ground_truth`: the reference mesh of a shape or a mesh file, with the
//! facts about it that sidecars record.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde_json::{Value, json};
use subdyn::mesh::PolyMesh;

use crate::measure::{enclosed_volume, surface_area};
use crate::shapes::{ShapeKind, ShapeParams, build_shape, surface_deviation};
use crate::sidecar::box_json;
use crate::topology::mesh_topology;

/// Shape parameters shared by `shape` and `scan`.
#[derive(Args, Debug, Clone)]
pub struct ShapeOptions {
    /// Sphere radius.
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "R",
        allow_negative_numbers = true
    )]
    pub radius: f64,
    /// Ellipsoid radii along x, y, z.
    #[arg(long, default_value = "1.5,1,0.6", value_name = "A,B,C", value_parser = parse_triple, allow_hyphen_values = true)]
    pub radii: [f64; 3],
    /// Torus major radius (centre of the tube to the axis).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "R",
        allow_negative_numbers = true
    )]
    pub major: f64,
    /// Torus minor radius (tube radius).
    #[arg(
        long,
        default_value_t = 0.35,
        value_name = "R",
        allow_negative_numbers = true
    )]
    pub minor: f64,
}

impl ShapeOptions {
    /// As [`ShapeParams`], with the mesh resolution (`None`: the shape's default).
    pub fn params(&self, resolution: Option<usize>) -> ShapeParams {
        ShapeParams {
            resolution,
            radius: self.radius,
            radii: self.radii,
            major: self.major,
            minor: self.minor,
        }
    }
}

/// `"a,b,c"` as three numbers.
pub fn parse_triple(s: &str) -> std::result::Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("expected three numbers A,B,C, got `{s}`"))?;
    <[f64; 3]>::try_from(v).map_err(|_| format!("expected three numbers A,B,C, got `{s}`"))
}

/// Where a ground truth comes from.
pub enum TruthSource {
    /// A built-in shape.
    Shape(ShapeKind, ShapeParams),
    /// A mesh file (any format subdyn reads).
    File(PathBuf),
}

/// A reference mesh and its description.
pub struct GroundTruth {
    /// The mesh.
    pub mesh: PolyMesh,
    /// `shape` name, or `"file"`.
    pub name: String,
    /// Facts for the sidecar: source, parameters, topology, box, area, volume.
    pub info: Value,
}

/// Builds or reads the ground truth.
pub fn ground_truth(source: &TruthSource) -> Result<GroundTruth> {
    match source {
        TruthSource::Shape(kind, params) => {
            let shape = build_shape(*kind, params)?;
            let (v_dev, c_dev) = surface_deviation(&shape.mesh, &shape.field);
            let mut info = describe(&shape.mesh);
            info["source"] = json!(format!("data-gen built-in shape `{}`", kind.name()));
            info["shape"] = json!(kind.name());
            info["analytic"] = shape.analytic;
            info["max_vertex_distance_to_analytic_surface"] = json!(v_dev);
            info["max_face_centroid_distance_to_analytic_surface"] = json!(c_dev);
            info["distance_note"] = json!(
                "first-order estimates |f|/|grad f| of how far the reference mesh is from the smooth surface it samples; scans are exact on the mesh itself"
            );
            Ok(GroundTruth {
                mesh: shape.mesh,
                name: kind.name().to_string(),
                info,
            })
        }
        TruthSource::File(path) => {
            let mesh = read_mesh_file(path)?;
            let mut info = describe(&mesh);
            info["source"] = json!(path.to_string_lossy());
            info["shape"] = json!("file");
            Ok(GroundTruth {
                mesh,
                name: "file".into(),
                info,
            })
        }
    }
}

/// Reads a mesh file that must have faces.
pub fn read_mesh_file(path: &Path) -> Result<PolyMesh> {
    if !path.exists() {
        anyhow::bail!("{}: no such mesh file", path.display());
    }
    let mesh =
        subdyn::io::read_mesh(path).with_context(|| format!("reading {}", path.display()))?;
    if mesh.num_faces() == 0 {
        anyhow::bail!(
            "{}: the file has no faces; a mesh is needed",
            path.display()
        );
    }
    Ok(mesh)
}

/// Topology, bounding box, area and volume of a mesh, as JSON.
pub fn describe(mesh: &PolyMesh) -> Value {
    let topology = mesh_topology(mesh);
    json!({
        "vertices": mesh.num_vertices(),
        "faces": mesh.num_faces(),
        "topology": topology,
        "bounding_box": box_json(&mesh.positions),
        "area": surface_area(mesh),
        "volume": if topology.closed { json!(enclosed_volume(mesh)) } else { Value::Null },
    })
}

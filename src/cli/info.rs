//! `subdyn info IN [--json]`: describe a mesh, a point file, a volume or a
//! lattice.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::json;

use subdyn::io::{MeshFormat, read_mesh_from_bytes, read_points_from_bytes};
use subdyn::math::{Point3, bbox_diagonal, bounding_box};
use subdyn::mesh::PolyMesh;

use super::common::{about_file, bbox_json, print_stdout, thousands};
use super::mesh_stats::{MeshStats, mesh_stats};

/// Arguments of `subdyn info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh or point file (.obj, .ply, .off, .xyz, optionally .gz), a volume
    /// (.nii, .nii.gz, .tif, .exr, .raw/.json, or a directory of slices), or a
    /// lattice (.json, as `subdyn lattice` writes it).
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `subdyn info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let path = &args.input;
    if subdyn::io::is_lattice_file(path) {
        return super::info_lattice::run(path, args.json);
    }
    if super::render::is_json(path) && !has_dims(path) {
        anyhow::bail!(
            "{}: neither lattice JSON (an object with a \"vertices\" list) nor a volume header (with \"dims\")",
            path.display()
        );
    }
    if super::info_volume::is_volume(path) {
        return super::info_volume::run(path, args.json);
    }
    let format = MeshFormat::from_path(path)?;
    let bytes = subdyn::io::read_input(path)?;
    let mesh = read_mesh_from_bytes(&bytes, format, path).map_err(|e| about_file(e, path))?;
    let cloud = read_points_from_bytes(&bytes, format, path).map_err(|e| about_file(e, path))?;
    let normals = cloud.normals.is_some();
    let text = if mesh.num_faces() == 0 {
        if args.json {
            json_line(&json!({
                "file": path.display().to_string(),
                "format": format.extension(),
                "kind": "points",
                "points": cloud.len(),
                "normals": normals,
                "bbox": bbox_json(&cloud.positions),
            }))
        } else {
            let mut s = header(path, format);
            let _ = writeln!(s, "points:               {}", thousands(cloud.len()));
            let _ = writeln!(
                s,
                "normals:              {}",
                if normals { "yes" } else { "no" }
            );
            s + &bbox_text(&cloud.positions)
        }
    } else {
        let stats = mesh_stats(&mesh);
        if args.json {
            let mut value = mesh_json(path, format, &mesh, &stats);
            value["normals"] = json!(normals);
            json_line(&value)
        } else {
            let text = mesh_text(path, format, &mesh, &stats);
            let normals = format!(
                "normals:              {}\n",
                if normals { "yes" } else { "no" }
            );
            // Normals go right after the face counts.
            match text.find("edges:") {
                Some(at) => format!("{}{normals}{}", &text[..at], &text[at..]),
                None => text + &normals,
            }
        }
    };
    print_stdout(&text)
}

/// Whether the JSON file at `path` is an object with a `"dims"` field (a
/// volume header); unreadable or invalid JSON counts as yes, so that the
/// volume reader names the problem.
fn has_dims(path: &Path) -> bool {
    subdyn::io::read_input(path)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .is_none_or(|v| v.get("dims").is_some())
}

fn json_line(value: &serde_json::Value) -> String {
    format!("{value}\n")
}

fn header(path: &Path, format: MeshFormat) -> String {
    format!(
        "file:                 {} ({})\n",
        path.display(),
        format.extension().to_uppercase()
    )
}

/// The `bounding box:` and `bbox diagonal:` lines.
pub fn bbox_text(points: &[Point3]) -> String {
    match bounding_box(points) {
        Some((lo, hi)) => format!(
            "bounding box:         [{:.6}, {:.6}, {:.6}] to [{:.6}, {:.6}, {:.6}]\nbbox diagonal:        {:.6}\n",
            lo.x,
            lo.y,
            lo.z,
            hi.x,
            hi.y,
            hi.z,
            bbox_diagonal(points)
        ),
        None => "bounding box:         empty\n".into(),
    }
}

/// `4: 6, 3: 2` style histogram.
fn histogram(h: &BTreeMap<usize, usize>) -> String {
    h.iter()
        .map(|(k, n)| format!("{k}: {}", thousands(*n)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn genus_text(stats: &MeshStats) -> String {
    let g: Vec<String> = stats
        .components
        .iter()
        .map(|c| match c.genus {
            Some(g) => g.to_string(),
            None => "n/a".into(),
        })
        .collect();
    let why = if stats.problem.is_some() {
        " (not a manifold, consistently oriented surface)"
    } else if stats.components.iter().any(|c| c.genus.is_none()) {
        " (genus is given for closed components only)"
    } else {
        ""
    };
    if g.len() == 1 {
        format!("{}{why}", g[0])
    } else {
        format!("{} by component{why}", g.join(", "))
    }
}

fn mesh_text(path: &Path, format: MeshFormat, mesh: &PolyMesh, s: &MeshStats) -> String {
    let mut t = header(path, format);
    let _ = writeln!(t, "vertices:             {}", thousands(s.vertices));
    let _ = writeln!(t, "faces:                {}", thousands(s.faces));
    let _ = writeln!(
        t,
        "edges:                {} ({} boundary, {} non-manifold)",
        thousands(s.edges),
        thousands(s.boundary_edges),
        thousands(s.non_manifold_edges)
    );
    let _ = writeln!(t, "face sizes:           {}", histogram(&s.face_sizes));
    let _ = writeln!(t, "boundary loops:       {}", thousands(s.boundary_loops));
    let _ = writeln!(t, "components:           {}", thousands(s.components.len()));
    let _ = writeln!(t, "euler characteristic: {}", s.euler());
    let _ = writeln!(t, "genus:                {}", genus_text(s));
    let _ = writeln!(t, "valences:             {}", histogram(&s.valences));
    let _ = writeln!(
        t,
        "isolated vertices:    {}",
        thousands(s.isolated_vertices)
    );
    let _ = writeln!(
        t,
        "subdividable:         {}",
        match &s.problem {
            None => "yes".to_string(),
            Some(why) => format!("no: {why}"),
        }
    );
    t + &bbox_text(&mesh.positions)
}

fn mesh_json(path: &Path, format: MeshFormat, mesh: &PolyMesh, s: &MeshStats) -> serde_json::Value {
    let hist = |h: &BTreeMap<usize, usize>| -> serde_json::Value {
        h.iter()
            .map(|(k, n)| (k.to_string(), json!(n)))
            .collect::<serde_json::Map<_, _>>()
            .into()
    };
    let components: Vec<_> = s
        .components
        .iter()
        .map(|c| {
            json!({
                "vertices": c.vertices,
                "edges": c.edges,
                "faces": c.faces,
                "boundary_edges": c.boundary_edges,
                "boundary_loops": c.boundary_loops,
                "euler": c.euler,
                "genus": c.genus,
            })
        })
        .collect();
    json!({
        "file": path.display().to_string(),
        "format": format.extension(),
        "kind": "mesh",
        "vertices": s.vertices,
        "faces": s.faces,
        "edges": s.edges,
        "boundary_edges": s.boundary_edges,
        "non_manifold_edges": s.non_manifold_edges,
        "boundary_loops": s.boundary_loops,
        "face_sizes": hist(&s.face_sizes),
        "components": components,
        "euler": s.euler(),
        "genus": if s.components.len() == 1 { json!(s.components[0].genus) } else { serde_json::Value::Null },
        "valences": hist(&s.valences),
        "isolated_vertices": s.isolated_vertices,
        "subdividable": s.problem.is_none(),
        "problem": s.problem,
        "bbox": bbox_json(&mesh.positions),
    })
}

//! Options shared by the verbs that refine a mesh: boundary rule and creases,
//! and the loading of the input mesh.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};

use subdyn::io::{read_creases, read_mesh};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{BoundaryRule, RefineOptions, Refiner};

use super::common::{about_file, thousands, warn};

/// Boundary interpolation, as on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Boundary {
    /// Boundary edges sharp, valence-2 boundary vertices stay corners.
    #[default]
    EdgeAndCorner,
    /// Boundary edges sharp, no corners.
    EdgeOnly,
}

impl Boundary {
    /// The library's rule.
    pub fn rule(self) -> BoundaryRule {
        match self {
            Boundary::EdgeAndCorner => BoundaryRule::EdgeAndCorner,
            Boundary::EdgeOnly => BoundaryRule::EdgeOnly,
        }
    }

    /// The command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            Boundary::EdgeAndCorner => "edge-and-corner",
            Boundary::EdgeOnly => "edge-only",
        }
    }
}

/// `--boundary` and `--creases`.
#[derive(Clone, Debug, Args)]
pub struct RefineArgs {
    /// Boundary rule.
    #[arg(long, value_enum, default_value_t = Boundary::EdgeAndCorner)]
    pub boundary: Boundary,
    /// Crease file: one line `i j s` per sharp edge (0-based vertex indices,
    /// sharpness s; s ≥ 10 or `inf` is infinitely sharp).
    #[arg(long, value_name = "FILE")]
    pub creases: Option<PathBuf>,
}

impl RefineArgs {
    /// Reads the crease file (if any) and builds the level-0 topology of
    /// `mesh`; errors name the mesh (`mesh_name`) or the crease file.
    pub fn refiner(&self, mesh: &PolyMesh, mesh_name: &str) -> anyhow::Result<Refiner> {
        let creases = match &self.creases {
            Some(path) => read_creases(path).map_err(|e| about_file(e, path))?,
            None => Vec::new(),
        };
        let options = RefineOptions {
            boundary: self.boundary.rule(),
            creases,
        };
        Refiner::new(mesh, &options).map_err(|e| match (&self.creases, &e) {
            (Some(path), subdyn::Error::Input(msg)) if msg.starts_with("crease") => {
                anyhow::anyhow!("{}: {msg} (the mesh is {mesh_name})", path.display())
            }
            _ => anyhow::Error::new(e).context(mesh_name.to_string()),
        })
    }
}

/// Reads a polygon mesh for a verb that needs faces; warns about isolated
/// vertices (they are carried along unchanged) unless `quiet`.
pub fn read_polygon_mesh(path: &Path, quiet: bool) -> anyhow::Result<PolyMesh> {
    let mesh = read_mesh(path).map_err(|e| about_file(e, path))?;
    if mesh.num_faces() == 0 {
        anyhow::bail!(
            "{}: the file has {} points but no faces; this command needs a polygon mesh \
             (`subdyn info` describes point files)",
            path.display(),
            thousands(mesh.num_vertices())
        );
    }
    warn_isolated(&mesh, &path.display().to_string(), quiet);
    Ok(mesh)
}

/// Warns (unless `quiet`) when some vertices belong to no face.
pub fn warn_isolated(mesh: &PolyMesh, name: &str, quiet: bool) {
    let mut used = vec![false; mesh.num_vertices()];
    for &v in &mesh.face_vertices {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    }
    let isolated: Vec<usize> = (0..used.len()).filter(|&v| !used[v]).collect();
    if let Some(first) = isolated.first() {
        warn(
            quiet,
            &format!(
                "{name}: {} isolated vertices (the first is vertex {first}) belong to no face; \
                 they are carried along unchanged",
                thousands(isolated.len())
            ),
        );
    }
}

/// `--quads` of the verbs that write a tessellated limit surface.
#[derive(Clone, Copy, Debug, Args)]
pub struct LimitFacesArgs {
    /// Write the limit surface as quads (default: triangles, each quad split
    /// along the diagonal whose two triangles face the same way best, which
    /// every mesh tool reads).
    #[arg(long)]
    pub quads: bool,
}

impl LimitFacesArgs {
    /// The faces to write for a quad tessellation: itself with `--quads`,
    /// else its triangles ([`subdyn::mesh::split_quads`]).
    pub fn mesh(self, tessellation: &PolyMesh) -> Cow<'_, PolyMesh> {
        if self.quads {
            Cow::Borrowed(tessellation)
        } else {
            Cow::Owned(subdyn::mesh::split_quads(tessellation))
        }
    }
}

//! Options shared by the verbs that refine a mesh: boundary rule and creases,
//! and the loading of the input mesh.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};

use subdyn::io::{read_mesh, read_obj_tags, read_tags};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{BoundaryRule, RefineOptions, Refiner, TriangleRule};
use subdyn::topology::CreaseMethod;

use super::common::{about_file, check_mesh_output, thousands, warn};

/// Boundary interpolation, as on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Boundary {
    /// Boundary edges sharp, valence-2 boundary vertices stay corners.
    #[default]
    EdgeAndCorner,
    /// Boundary edges sharp, no corners.
    EdgeOnly,
    /// No surface along the boundary: the faces at boundary vertices are holes.
    None,
}

impl Boundary {
    /// The library's rule.
    pub fn rule(self) -> BoundaryRule {
        match self {
            Boundary::EdgeAndCorner => BoundaryRule::EdgeAndCorner,
            Boundary::EdgeOnly => BoundaryRule::EdgeOnly,
            Boundary::None => BoundaryRule::None,
        }
    }
}

/// How semi-sharp creases decay, as on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum CreaseMethodArg {
    /// Sharpness − 1 per level.
    #[default]
    Uniform,
    /// Each half of an edge towards the mean of its semi-sharp neighbours (OpenSubdiv's Chaikin).
    Chaikin,
}

/// The edge rule next to triangles, as on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum TriangleRuleArg {
    /// Catmull-Clark's rule.
    #[default]
    Catmark,
    /// OpenSubdiv's smooth-triangle rule (face weight 0.47 next to a triangle).
    Smooth,
}

/// `--boundary`, `--creases`, `--crease-method` and `--triangle-rule`. An
/// OBJ input's own OpenSubdiv tags (`t crease`, `t corner`, `t hole`,
/// `t interpolateboundary`, `t creasemethod`, `t smoothtriangles`) apply
/// too; a flag given on the command line wins over the file's tag.
#[derive(Clone, Debug, Args)]
pub struct RefineArgs {
    /// Boundary rule (default edge-and-corner, or the OBJ's `t interpolateboundary`).
    #[arg(long, value_enum)]
    pub boundary: Option<Boundary>,
    /// Tag file: lines `i j s` (the edge between vertices i and j has
    /// sharpness s), `v i s` (vertex i has sharpness s: a corner while it
    /// lasts) and `h f` (face f is a hole); 0-based indices, s ≥ 10 or
    /// `inf` infinitely sharp.
    #[arg(long, value_name = "FILE")]
    pub creases: Option<PathBuf>,
    /// How semi-sharp creases decay (default uniform, or the OBJ's `t creasemethod`).
    #[arg(long, value_enum)]
    pub crease_method: Option<CreaseMethodArg>,
    /// The edge rule next to triangles (default catmark, or the OBJ's `t smoothtriangles`).
    #[arg(long, value_enum)]
    pub triangle_rule: Option<TriangleRuleArg>,
}

impl RefineArgs {
    /// Reads the OBJ tags of `mesh_path` (for an `.obj` or `.obj.gz`) and the
    /// tag file (if any), and builds the level-0 topology of `mesh`; errors
    /// name the mesh or the tag file.
    pub fn refiner(&self, mesh: &PolyMesh, mesh_path: &Path) -> anyhow::Result<Refiner> {
        let mesh_name = mesh_path.display().to_string();
        let options = self.options(mesh_path)?;
        Refiner::new(mesh, &options).map_err(|e| match (&self.creases, &e) {
            (Some(path), subdyn::Error::Input(msg))
                if ["crease", "vertex sharpness", "hole"]
                    .iter()
                    .any(|p| msg.starts_with(p)) =>
            {
                anyhow::anyhow!("{}: {msg} (the mesh is {mesh_name})", path.display())
            }
            _ => anyhow::Error::new(e).context(mesh_name),
        })
    }

    /// The refinement options: the OBJ tags of `mesh_path` (for an `.obj` or
    /// `.obj.gz`), the tag file's, then the flags.
    pub fn options(&self, mesh_path: &Path) -> anyhow::Result<RefineOptions> {
        let name = mesh_path.display().to_string().to_ascii_lowercase();
        let mut options = RefineOptions::default();
        if name.ends_with(".obj") || name.ends_with(".obj.gz") {
            let tags = read_obj_tags(mesh_path).map_err(|e| about_file(e, mesh_path))?;
            options = tags.apply(options);
        }
        if let Some(path) = &self.creases {
            read_tags(path)
                .map_err(|e| about_file(e, path))?
                .add_to(&mut options);
        }
        if let Some(b) = self.boundary {
            options.boundary = b.rule();
        }
        if let Some(m) = self.crease_method {
            options.crease_method = match m {
                CreaseMethodArg::Uniform => CreaseMethod::Uniform,
                CreaseMethodArg::Chaikin => CreaseMethod::Chaikin,
            };
        }
        if let Some(t) = self.triangle_rule {
            options.triangles = match t {
                TriangleRuleArg::Catmark => TriangleRule::Catmark,
                TriangleRuleArg::Smooth => TriangleRule::Smooth,
            };
        }
        Ok(options)
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

/// `--limit-out`, `--tess` and `--quads` of the verbs that make a control
/// mesh (`fit`, `recover`).
#[derive(Clone, Debug, Args)]
pub struct LimitOutArgs {
    /// Also write a dense limit-surface tessellation (K×K per quad, see --tess).
    #[arg(long, value_name = "SURF")]
    pub limit_out: Option<PathBuf>,
    /// Tessellation rate of --limit-out (and of recover's slice contours):
    /// 1 to 64.
    #[arg(long, value_name = "K", default_value_t = 4)]
    pub tess: usize,
    #[command(flatten)]
    pub faces: LimitFacesArgs,
}

impl LimitOutArgs {
    /// Checks the output path and the rate before any work is done.
    pub fn check(&self) -> anyhow::Result<()> {
        if let Some(p) = &self.limit_out {
            check_mesh_output(p)?;
        }
        if self.tess == 0 || self.tess > 64 {
            anyhow::bail!("--tess {} is out of range: expected 1 to 64", self.tess);
        }
        Ok(())
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

//! `subdyn subdivide --scheme doo-sabin|non-uniform`: refinement with the
//! schemes other than uniform Catmull-Clark.

use std::path::PathBuf;

use clap::ValueEnum;

use subdyn::io::read_tags;
use subdyn::math::Real;
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{NonUniformHierarchy, doo_sabin_refine};
use subdyn::topology::{Level, find_edge};

use super::common::about_file;

/// The subdivision scheme of `subdyn subdivide`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Scheme {
    /// Uniform Catmull-Clark (with boundaries and creases).
    #[default]
    CatmullClark,
    /// Doo-Sabin (boundary faces refined like interior ones; the surface
    /// does not reach the boundary polygon).
    DooSabin,
    /// Non-uniform Catmull-Clark with a knot interval per edge (`--knots`).
    NonUniform,
}

impl Scheme {
    /// The command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::CatmullClark => "catmull-clark",
            Scheme::DooSabin => "doo-sabin",
            Scheme::NonUniform => "non-uniform",
        }
    }
}

/// Knot intervals per edge: 1 everywhere, except the edges listed in `knots`
/// (lines `i j d`, the edge between vertices `i` and `j` gets interval `d`).
pub fn knot_intervals(level: &Level, knots: Option<&PathBuf>) -> anyhow::Result<Vec<Real>> {
    let mut d = vec![1.0; level.num_edges()];
    if let Some(path) = knots {
        let tags = read_tags(path).map_err(|e| about_file(e, path))?;
        if !tags.corners.is_empty() || !tags.holes.is_empty() {
            anyhow::bail!(
                "{}: a knot file has `i j interval` lines only (found vertex or hole lines)",
                path.display()
            );
        }
        for (i, j, s) in tags.creases {
            let e = find_edge(level, i, j).ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: vertices {i} and {j} are not joined by an edge",
                    path.display()
                )
            })?;
            if !s.is_finite() {
                anyhow::bail!(
                    "{}: edge {i}-{j} has interval {s}; intervals must be finite",
                    path.display()
                );
            }
            d[e] = s;
        }
    }
    Ok(d)
}

/// `mesh` refined `levels` times with `scheme` (not Catmull-Clark).
pub fn refine_other(
    mesh: &PolyMesh,
    scheme: Scheme,
    levels: usize,
    knots: Option<&PathBuf>,
) -> anyhow::Result<PolyMesh> {
    match scheme {
        Scheme::DooSabin => Ok(doo_sabin_refine(mesh, levels)?.finest().clone()),
        _ => {
            let level = Level::from_mesh(mesh)?;
            let d = knot_intervals(&level, knots)?;
            let h = NonUniformHierarchy::new(level, d, levels)?;
            let positions = h.stencil_to_level(levels)?.apply(&mesh.positions)?;
            let l = &h.levels[levels];
            Ok(PolyMesh {
                positions,
                face_offsets: l.face_offsets.clone(),
                face_vertices: l.face_verts.clone(),
            })
        }
    }
}

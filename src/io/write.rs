//! `write_mesh` and `write_points`: check the data, pick the writer by
//! extension, compress for `.gz`, and write atomically.

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::Compression;
use flate2::write::GzEncoder;

use super::atomic::atomic_write;
use super::creases::{SubdivisionTags, write_tags};
use super::format::{MeshFormat, is_gzip_path};
use super::{obj, off, ply, xyz};
use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, first_non_finite};
use crate::mesh::{PointCloud, PolyMesh};

/// What a writer writes: points, optional normals and optional faces.
pub(crate) struct Geometry<'a> {
    /// Vertex positions.
    pub positions: &'a [Point3],
    /// One normal per position, or none.
    pub normals: Option<&'a [Vector3]>,
    /// The mesh whose faces are written (its positions are `positions`).
    pub mesh: Option<&'a PolyMesh>,
    /// Sharp edges `(i, j, s)` of the mesh: written by the OBJ writer only,
    /// as OpenSubdiv's `t crease` tags.
    pub creases: &'a [(u32, u32, Real)],
}

impl Geometry<'_> {
    /// Number of faces (0 for a point cloud).
    pub fn num_faces(&self) -> usize {
        self.mesh.map_or(0, PolyMesh::num_faces)
    }

    /// The faces, 0-based (none for a point cloud).
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.mesh.into_iter().flat_map(PolyMesh::faces)
    }
}

/// Writes `mesh` in the format of `path`'s extension, atomically
/// ([`atomic_write`]); a trailing `.gz` compresses the output.
///
/// - OBJ: `v` lines, `vn` lines when `normals` are given, `f` lines with
///   1-based indices (`f a//a …` with normals).
/// - PLY: binary little endian; `x y z` (and `nx ny nz`) as `double`; faces as
///   `list uchar int`, or `list uint int` when a face has more than 255 vertices.
/// - OFF: `OFF` (`NOFF` with normals), 0-based faces.
/// - XYZ: positions only, `x y z` (`x y z nx ny nz` with normals).
///
/// Numbers are written in the shortest form that reads back exactly. The mesh
/// is validated first; `normals` must have one finite vector per vertex.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// # let path = dir.path().join("quad.ply");
/// use subdyn::{io, math::Point3, mesh::PolyMesh};
/// let p = |x, y| Point3::new(x, y, 0.0);
/// let quad = PolyMesh::from_faces(vec![p(0., 0.), p(1., 0.), p(1., 1.), p(0., 1.)], &[vec![0, 1, 2, 3]])?;
/// io::write_mesh(&path, &quad, None)?;
/// assert_eq!(io::read_mesh(&path)?, quad);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn write_mesh(
    path: impl AsRef<Path>,
    mesh: &PolyMesh,
    normals: Option<&[Vector3]>,
) -> Result<()> {
    write_mesh_with_creases(path, mesh, normals, &[])
}

/// [`write_mesh`] with sharp edges `(i, j, s)`: an OBJ file carries them as
/// OpenSubdiv's tags, one `t crease 2/1/0 i j s` line each (0-based
/// indices, `s ≥ 10` infinitely sharp), which [`super::read_obj_tags`] and
/// every verb that reads a control mesh apply; mesh readers without
/// subdivision skip `t` lines. The other formats have no place for them
/// ([`write_control_mesh`] puts them in a tag file beside the mesh).
pub fn write_mesh_with_creases(
    path: impl AsRef<Path>,
    mesh: &PolyMesh,
    normals: Option<&[Vector3]>,
    creases: &[(u32, u32, Real)],
) -> Result<()> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    mesh.validate()?;
    check_normals(normals, mesh.num_vertices())?;
    let n = mesh.num_vertices();
    if let Some(&(i, j, s)) = creases
        .iter()
        .find(|&&(i, j, s)| i as usize >= n || j as usize >= n || i == j || s.is_nan() || s < 0.0)
    {
        return Err(Error::input(format!(
            "crease {i} {j} {s} is not an edge sharpness of a mesh of {n} vertices"
        )));
    }
    let geometry = Geometry {
        positions: &mesh.positions,
        normals,
        mesh: Some(mesh),
        creases,
    };
    write_geometry(path, format, &geometry)
}

/// Writes a control mesh with its sharp edges `(i, j, s)`: an OBJ file
/// carries them ([`write_mesh_with_creases`]); any other format gets them
/// in a tag file beside it, `PATH.creases` (`i j s` lines, [`write_tags`]),
/// whose path is returned. Without creases only the mesh is written.
pub fn write_control_mesh(
    path: impl AsRef<Path>,
    mesh: &PolyMesh,
    creases: &[(u32, u32, Real)],
) -> Result<Option<PathBuf>> {
    let path = path.as_ref();
    let obj = MeshFormat::from_path(path)? == MeshFormat::Obj;
    write_mesh_with_creases(path, mesh, None, if obj { creases } else { &[] })?;
    if obj || creases.is_empty() {
        return Ok(None);
    }
    let mut name = path.as_os_str().to_owned();
    name.push(".creases");
    let tags_path = PathBuf::from(name);
    let tags = SubdivisionTags {
        creases: creases.to_vec(),
        ..Default::default()
    };
    write_tags(&tags_path, &tags)?;
    Ok(Some(tags_path))
}

/// Writes the points of `cloud` (and its normals, when it has them) in the
/// format of `path`'s extension, atomically; a trailing `.gz` compresses.
/// XYZ: 3 or 6 columns; PLY: a vertex element only; OBJ: `v` (and `vn`)
/// lines; OFF: a file with 0 faces (`NOFF` with normals).
pub fn write_points(path: impl AsRef<Path>, cloud: &PointCloud) -> Result<()> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    if let Some(i) = first_non_finite(&cloud.positions) {
        return Err(Error::non_finite(format!(
            "point {i} has a non-finite coordinate ({}, {}, {})",
            cloud.positions[i].x, cloud.positions[i].y, cloud.positions[i].z
        )));
    }
    check_normals(cloud.normals.as_deref(), cloud.len())?;
    let geometry = Geometry {
        positions: &cloud.positions,
        normals: cloud.normals.as_deref(),
        mesh: None,
        creases: &[],
    };
    write_geometry(path, format, &geometry)
}

/// Normals, when given, must be one finite vector per vertex.
fn check_normals(normals: Option<&[Vector3]>, num_vertices: usize) -> Result<()> {
    let Some(normals) = normals else {
        return Ok(());
    };
    if normals.len() != num_vertices {
        return Err(Error::size_mismatch(format!(
            "{} normals for {num_vertices} vertices",
            normals.len()
        )));
    }
    match normals
        .iter()
        .position(|n| !n.iter().all(|c| c.is_finite()))
    {
        Some(i) => Err(Error::non_finite(format!("normal {i} is not finite"))),
        None => Ok(()),
    }
}

/// Runs the format's writer inside [`atomic_write`], through gzip for `.gz`.
fn write_geometry(path: &Path, format: MeshFormat, geometry: &Geometry) -> Result<()> {
    let gzip = is_gzip_path(path);
    atomic_write(path, |w| {
        if gzip {
            let mut encoder = GzEncoder::new(w, Compression::default());
            write_format(&mut encoder, format, geometry)?;
            encoder.finish()?;
            Ok(())
        } else {
            write_format(w, format, geometry)
        }
    })
}

/// Dispatches to the format's writer.
fn write_format(w: &mut dyn Write, format: MeshFormat, geometry: &Geometry) -> std::io::Result<()> {
    match format {
        MeshFormat::Obj => obj::write_obj(w, geometry),
        MeshFormat::Ply => ply::write_ply(w, geometry),
        MeshFormat::Off => off::write_off(w, geometry),
        MeshFormat::Xyz => xyz::write_xyz(w, geometry),
    }
}

/// Writes `x` in the shortest decimal form that parses back to the same
/// `f64`, switching to exponent notation for very large or small magnitudes.
pub(crate) fn write_real(w: &mut dyn Write, x: Real) -> std::io::Result<()> {
    let a = x.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(w, "{x}")
    } else {
        write!(w, "{x:e}")
    }
}

/// Writes `x y z` (then ` nx ny nz` when `normal` is given) and a newline.
pub(crate) fn write_point_line(
    w: &mut dyn Write,
    p: &Point3,
    normal: Option<&Vector3>,
) -> std::io::Result<()> {
    write_real(w, p.x)?;
    for c in [p.y, p.z] {
        w.write_all(b" ")?;
        write_real(w, c)?;
    }
    if let Some(n) = normal {
        for c in [n.x, n.y, n.z] {
            w.write_all(b" ")?;
            write_real(w, c)?;
        }
    }
    w.write_all(b"\n")
}

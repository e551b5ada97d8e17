//! `read_mesh` and `read_points`: pick the reader by format, from a file or
//! from bytes already in memory.

use std::path::Path;

use super::format::MeshFormat;
use super::raw::RawGeometry;
use super::source::{contents, read_input};
use super::{obj, off, ply, xyz};
use crate::error::Result;
use crate::mesh::{PointCloud, PolyMesh};

/// Reads a polygon mesh from an OBJ, PLY or OFF file (optionally `.gz`);
/// faces keep their size (quads stay quads). An XYZ file, or a PLY file without
/// a face element, gives a mesh with vertices and no faces.
///
/// Errors name the file and the line (or, in binary PLY, the element): bad
/// numbers, NaN or infinite coordinates, face indices out of range, truncated
/// data, an empty file, a file with no vertices, an unknown extension.
///
/// ```no_run
/// let cage = subdyn::io::read_mesh("cage.obj")?;
/// println!("{} vertices, {} faces", cage.num_vertices(), cage.num_faces());
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn read_mesh(path: impl AsRef<Path>) -> Result<PolyMesh> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    read_mesh_from_bytes(&read_input(path)?, format, path)
}

/// Reads the points of any supported file (optionally `.gz`), with their
/// normals when the file has them: PLY `nx ny nz`, OBJ `vn` (only when there is
/// one per vertex), OFF `NOFF` columns, XYZ's six-column lines. Faces are read
/// (and checked) but dropped.
///
/// ```no_run
/// let scan = subdyn::io::read_points("../shared/data/scans/bun045.ply")?;
/// assert_eq!(scan.len(), 40_097);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn read_points(path: impl AsRef<Path>) -> Result<PointCloud> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    read_points_from_bytes(&read_input(path)?, format, path)
}

/// [`read_mesh`] for a file already in memory (for instance `include_bytes!`);
/// gzip data is recognised by its magic number. `name` only labels errors.
///
/// ```
/// use std::path::Path;
/// use subdyn::io::{read_mesh_from_bytes, MeshFormat};
/// let text = b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
/// let quad = read_mesh_from_bytes(text, MeshFormat::Off, Path::new("quad.off")).unwrap();
/// assert_eq!(quad.face(0), &[0, 1, 2, 3]);
/// ```
pub fn read_mesh_from_bytes(bytes: &[u8], format: MeshFormat, name: &Path) -> Result<PolyMesh> {
    parse(bytes, format, name)?.into_mesh(name)
}

/// [`read_points`] for a file already in memory; `name` only labels errors.
pub fn read_points_from_bytes(bytes: &[u8], format: MeshFormat, name: &Path) -> Result<PointCloud> {
    parse(bytes, format, name)?.into_cloud(name)
}

/// Reads OBJ text already in memory (for instance an embedded default cage);
/// `name` only labels errors.
///
/// ```
/// use std::path::Path;
/// let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
/// let quad = subdyn::io::read_obj_from_bytes(obj, Path::new("quad.obj")).unwrap();
/// assert_eq!(quad.num_faces(), 1);
/// ```
pub fn read_obj_from_bytes(bytes: &[u8], name: &Path) -> Result<PolyMesh> {
    read_mesh_from_bytes(bytes, MeshFormat::Obj, name)
}

/// Decompresses if needed and runs the format's parser.
fn parse(bytes: &[u8], format: MeshFormat, name: &Path) -> Result<RawGeometry> {
    let bytes = contents(bytes, name)?;
    match format {
        MeshFormat::Obj => obj::parse_obj(&bytes, name),
        MeshFormat::Ply => ply::parse_ply(&bytes, name),
        MeshFormat::Off => off::parse_off(&bytes, name),
        MeshFormat::Xyz => xyz::parse_xyz(&bytes, name),
    }
}

//! `MeshFormat`: which file format a path names, decided by its extension.

use std::path::Path;

use crate::error::{Error, Result};

/// The extensions [`MeshFormat::from_path`] accepts, for error messages.
const SUPPORTED: &str = ".obj, .ply, .off, .xyz (each optionally followed by .gz)";

/// A mesh or point-cloud file format.
///
/// ```
/// use std::path::Path;
/// use subdyn::io::MeshFormat;
/// assert_eq!(MeshFormat::from_path(Path::new("scan.PLY")).unwrap(), MeshFormat::Ply);
/// assert_eq!(MeshFormat::from_path(Path::new("dragon.ply.gz")).unwrap(), MeshFormat::Ply);
/// assert!(MeshFormat::from_path(Path::new("notes.txt")).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (`v`, `vn`, `f` lines; polygons of any size).
    Obj,
    /// Stanford PLY, ASCII or binary in either byte order.
    Ply,
    /// Object File Format (`OFF`, also `NOFF`, `COFF`).
    Off,
    /// Plain points, `x y z` or `x y z nx ny nz` per line.
    Xyz,
}

impl MeshFormat {
    /// The format named by `path`'s extension, compared case-insensitively.
    /// A trailing `.gz` is looked through (`bunny.ply.gz` is PLY, gzip-compressed).
    ///
    /// An unknown or missing extension is an [`Error::Input`] that names the path
    /// and lists the supported extensions.
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        let extension = name.rsplit_once('.').map(|(_, ext)| ext);
        match extension {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("off") => Ok(MeshFormat::Off),
            Some("xyz") => Ok(MeshFormat::Xyz),
            Some(other) => Err(Error::unsupported(format!(
                "{}: unknown file extension `.{other}`; supported: {SUPPORTED}",
                path.display()
            ))),
            None => Err(Error::unsupported(format!(
                "{}: no file extension to tell the format; supported: {SUPPORTED}",
                path.display()
            ))),
        }
    }

    /// The usual extension of the format, without the dot (`"ply"`).
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Off => "off",
            MeshFormat::Xyz => "xyz",
        }
    }
}

/// True when `path` ends in `.gz` (any case): the file is gzip-compressed.
pub(crate) fn is_gzip_path(path: &Path) -> bool {
    path.file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase().ends_with(".gz"))
        .unwrap_or(false)
}

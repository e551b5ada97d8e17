//! Which volume format a path holds, from what it is (a directory) and its
//! extension.

use std::path::Path;

use crate::error::{Error, Result};

/// A volume format [`read_volume`](super::read_volume) reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeFormat {
    /// A directory of 2D slice images (PNG 8/16-bit grey, TIFF, or
    /// single-channel EXR), `z` = the number in the file name.
    SliceDirectory,
    /// One TIFF file, a page per `z` slice (`.tif`, `.tiff`).
    Tiff,
    /// One single-channel OpenEXR image: a volume one slice thick (`.exr`).
    Exr,
    /// NIfTI-1 single file (`.nii`, `.nii.gz`).
    Nifti,
    /// Headerless samples described by a JSON sidecar (`.raw` with
    /// `BASE.json` beside it, or the `.json` itself).
    Raw,
}

impl VolumeFormat {
    /// The format of `path`: a directory is a slice stack, files go by
    /// extension (case-insensitive). Errors name the path and the
    /// extensions understood.
    pub fn from_path(path: &Path) -> Result<VolumeFormat> {
        if path.is_dir() {
            return Ok(VolumeFormat::SliceDirectory);
        }
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let by_ext = [
            (".nii.gz", VolumeFormat::Nifti),
            (".nii", VolumeFormat::Nifti),
            (".tiff", VolumeFormat::Tiff),
            (".tif", VolumeFormat::Tiff),
            (".exr", VolumeFormat::Exr),
            (".raw", VolumeFormat::Raw),
            (".json", VolumeFormat::Raw),
        ];
        if let Some((_, f)) = by_ext.iter().find(|(e, _)| name.ends_with(e)) {
            return Ok(*f);
        }
        let why = if name.ends_with(".hdr") || name.ends_with(".img") {
            "two-file ANALYZE / NIfTI (.hdr + .img) is not read; convert it to a single .nii"
        } else {
            "not a volume: give a directory of slices, .nii, .nii.gz, .tif, .tiff, .exr, .raw or .json"
        };
        Err(Error::parse(path, 0, why))
    }

    /// A short name for messages: `slice directory`, `TIFF`, …
    pub fn name(self) -> &'static str {
        match self {
            VolumeFormat::SliceDirectory => "slice directory",
            VolumeFormat::Tiff => "TIFF",
            VolumeFormat::Exr => "EXR",
            VolumeFormat::Nifti => "NIfTI-1",
            VolumeFormat::Raw => "raw + JSON",
        }
    }
}

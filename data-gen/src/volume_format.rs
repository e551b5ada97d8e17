//! Output formats of `data-gen volume` and where each puts its files.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::ValueEnum;
use serde::Serialize;

/// A volume file format (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum VolumeFormat {
    /// Directory of 8-bit grey PNG slices `slice_<z>.png`.
    Png8,
    /// Directory of 16-bit grey PNG slices `slice_<z>.png`.
    Png16,
    /// One multi-page TIFF, a 16-bit grey page per z slice.
    Tiff,
    /// One multi-page TIFF, a 32-bit float page per z slice.
    TiffF32,
    /// Directory of single-channel (`Y`) f32 OpenEXR slices `slice_<z>.exr`.
    Exr,
    /// Little-endian f32, x fastest, then y, then z; the JSON sidecar is the header.
    Raw,
    /// NIfTI-1 single file `.nii`, FLOAT32.
    Nifti,
    /// NIfTI-1 single file, gzip-compressed `.nii.gz`.
    NiftiGz,
}

impl VolumeFormat {
    /// The format named by `path`'s extension; `None` for a path without a
    /// volume extension (a directory name).
    pub fn from_extension(path: &Path) -> Option<VolumeFormat> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        [
            (".nii.gz", VolumeFormat::NiftiGz),
            (".nii", VolumeFormat::Nifti),
            (".tiff", VolumeFormat::Tiff),
            (".tif", VolumeFormat::Tiff),
            (".raw", VolumeFormat::Raw),
        ]
        .into_iter()
        .find(|(ext, _)| name.ends_with(ext))
        .map(|(_, f)| f)
    }

    /// Whether the volume is a directory of slice files.
    pub fn is_stack(self) -> bool {
        matches!(
            self,
            VolumeFormat::Png8 | VolumeFormat::Png16 | VolumeFormat::Exr
        )
    }

    /// File extensions a single-file output may carry (the first is appended
    /// when none is given).
    fn extensions(self) -> &'static [&'static str] {
        match self {
            VolumeFormat::Tiff | VolumeFormat::TiffF32 => &[".tif", ".tiff"],
            VolumeFormat::Raw => &[".raw"],
            VolumeFormat::Nifti => &[".nii"],
            VolumeFormat::NiftiGz => &[".nii.gz"],
            VolumeFormat::Png8 | VolumeFormat::Png16 | VolumeFormat::Exr => &[],
        }
    }
}

/// Where one run writes.
#[derive(Clone, Debug)]
pub struct OutputPaths {
    /// The volume: a directory for stacks, a file otherwise.
    pub volume: PathBuf,
    /// The JSON sidecar (`OUT/volume.json` for stacks, `BASE.json` for files).
    pub sidecar: PathBuf,
    /// The ground-truth mesh (`OUT/truth.obj` for stacks, `BASE.truth.obj` for files).
    pub truth: PathBuf,
}

/// Picks the format (`--format`, else `-o`'s extension, else a 16-bit PNG
/// stack) and the output paths. A single-file output without its extension
/// gets it appended; `BASE` is the output without its extension.
pub fn output_paths(
    out: &Path,
    format: Option<VolumeFormat>,
) -> Result<(VolumeFormat, OutputPaths)> {
    let by_ext = VolumeFormat::from_extension(out);
    let format = match (format, by_ext) {
        (Some(f), Some(e))
            if f != e && !(f == VolumeFormat::TiffF32 && e == VolumeFormat::Tiff) =>
        {
            bail!(
                "{}: the extension says {} but --format says {}",
                out.display(),
                e.to_possible_value()
                    .map_or(String::new(), |v| v.get_name().to_string()),
                f.to_possible_value()
                    .map_or(String::new(), |v| v.get_name().to_string())
            )
        }
        (Some(f), _) => f,
        (None, Some(e)) => e,
        (None, None) => VolumeFormat::Png16,
    };
    let name = match out.file_name() {
        Some(n) => n.to_string_lossy().into_owned(),
        None => bail!(
            "{}: not a file or directory name to write to",
            out.display()
        ),
    };
    if format.is_stack() {
        return Ok((
            format,
            OutputPaths {
                volume: out.to_path_buf(),
                sidecar: out.join("volume.json"),
                truth: out.join("truth.obj"),
            },
        ));
    }
    let lower = name.to_ascii_lowercase();
    let (file, base) = match format.extensions().iter().find(|e| lower.ends_with(*e)) {
        Some(ext) => (name.clone(), name[..name.len() - ext.len()].to_string()),
        None => (format!("{name}{}", format.extensions()[0]), name.clone()),
    };
    if base.is_empty() {
        bail!(
            "{}: the output needs a name before its extension",
            out.display()
        );
    }
    Ok((
        format,
        OutputPaths {
            volume: out.with_file_name(file),
            sidecar: out.with_file_name(format!("{base}.json")),
            truth: out.with_file_name(format!("{base}.truth.obj")),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_follow_the_extension() {
        let (f, p) = output_paths(Path::new("d/vol.nii.gz"), None).unwrap();
        assert_eq!(f, VolumeFormat::NiftiGz);
        assert_eq!(p.sidecar, Path::new("d/vol.json"));
        assert_eq!(p.truth, Path::new("d/vol.truth.obj"));
        let (f, p) = output_paths(Path::new("d/vol"), Some(VolumeFormat::Raw)).unwrap();
        assert_eq!(f, VolumeFormat::Raw);
        assert_eq!(p.volume, Path::new("d/vol.raw"));
        let (f, p) = output_paths(Path::new("stack"), None).unwrap();
        assert_eq!(f, VolumeFormat::Png16);
        assert_eq!(p.sidecar, Path::new("stack/volume.json"));
        assert!(output_paths(Path::new("v.nii"), Some(VolumeFormat::Tiff)).is_err());
        let (f, _) = output_paths(Path::new("v.tif"), Some(VolumeFormat::TiffF32)).unwrap();
        assert_eq!(f, VolumeFormat::TiffF32);
    }
}

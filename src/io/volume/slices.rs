//! Slice directories: one 2D image per z, PNG (8/16-bit grey), TIFF or
//! single-channel EXR, stacked in the order of the number in each file name
//! (`slice_9.png` before `slice_10.png`: numbers, not text, are compared).
//!
//! Conventions: column = x, row = y (the first row of the file is y = 0),
//! slice order = z. Files with other extensions (`volume.json`,
//! `truth.obj`, …) are ignored; slice files of two kinds (`.png` and
//! `.tif`) in one directory are an error, as are slices of different sizes
//! or bit depths (naming the first file that differs). Colour PNGs are
//! converted to grey (luma, Rec. 709 weights, as the `image` crate does)
//! with a note; an alpha channel is dropped with a note. A TIFF file
//! contributes every page it has, in page order.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use image::DynamicImage;
use rayon::prelude::*;

use super::decoded::{Decoded, Placement};
use super::exr::exr_slice;
use super::tiff::{tiff_pages, tiff_samples};
use crate::error::{Error, Result};

/// One decoded 2D image.
#[derive(Clone, Debug)]
pub(crate) struct Slice {
    /// Columns (x).
    pub width: usize,
    /// Rows (y).
    pub height: usize,
    /// Stored sample kind, for mixed-depth checks: `8-bit grey`, `32-bit float`, …
    pub kind: String,
    /// Samples, row 0 first, as f32.
    pub samples: Vec<f32>,
    /// A remark (colour converted, alpha dropped).
    pub note: Option<String>,
}

/// Reads the slice directory `dir`.
pub(crate) fn read_slice_dir(dir: &Path) -> Result<Decoded> {
    let files = slice_files(dir)?;
    let ext = files[0]
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let samples = files
        .iter()
        .map(|f| file_samples(f))
        .try_fold(0u64, |sum, n| n.map(|n| sum.saturating_add(n)))?;
    check_decoded(
        &format!(
            "decoding the {} slice files of {}",
            files.len(),
            dir.display()
        ),
        samples,
    )?;
    let decoded: Vec<Vec<Slice>> = files
        .par_iter()
        .map(|f| decode_file(f))
        .collect::<Result<_>>()?;
    let slices: Vec<(&PathBuf, Slice)> = files
        .iter()
        .zip(decoded)
        .flat_map(|(f, pages)| pages.into_iter().map(move |s| (f, s)))
        .collect();
    let stack = stacked(slices)?;
    let source = format!(
        "{} .{ext} slices ({}), {} to {}",
        stack.dims[2],
        stack.kind,
        name(&files[0]),
        name(&files[files.len() - 1])
    );
    Ok(Decoded {
        dims: stack.dims,
        data: stack.data,
        placement: Placement::Grid { spacing: None },
        source,
        notes: stack.notes,
        physical: false,
    })
}

/// Slices stacked into one volume.
pub(crate) struct Stacked {
    /// Width, height, number of slices.
    pub dims: [usize; 3],
    /// The slices' common sample kind.
    pub kind: String,
    /// The slices' distinct notes.
    pub notes: Vec<String>,
    /// Samples, x fastest.
    pub data: Vec<f32>,
}

/// Stacks the slices in order (freeing each once copied, so the peak memory
/// stays near one volume), checking that they agree in size and kind.
pub(crate) fn stacked(slices: Vec<(&PathBuf, Slice)>) -> Result<Stacked> {
    let Some((first, s0)) = slices.first() else {
        return Err(Error::input("no slices to stack"));
    };
    let (first, width, height, kind) = ((*first).clone(), s0.width, s0.height, s0.kind.clone());
    let depth = slices.len();
    let mut data = Vec::with_capacity(width * height * depth);
    let mut notes = BTreeSet::new();
    for (path, s) in slices {
        if (s.width, s.height) != (width, height) {
            return Err(Error::parse(
                path.as_path(),
                0,
                format!(
                    "slice is {}×{} but {} is {width}×{height}: every slice must have the same size",
                    s.width,
                    s.height,
                    name(&first),
                ),
            ));
        }
        if s.kind != kind {
            return Err(Error::parse(
                path.as_path(),
                0,
                format!(
                    "slice is {} but {} is {kind}: mixed bit depths",
                    s.kind,
                    name(&first),
                ),
            ));
        }
        data.extend_from_slice(&s.samples);
        notes.extend(s.note);
    }
    Ok(Stacked {
        dims: [width, height, depth],
        kind,
        notes: notes.into_iter().collect(),
        data,
    })
}

/// The slice files of `dir` sorted by the number in their names.
fn slice_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut found: Vec<(u64, PathBuf)> = Vec::new();
    let mut kinds = BTreeSet::new();
    for entry in entries {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let kind = match ext.as_str() {
            "png" => "PNG",
            "tif" | "tiff" => "TIFF",
            "exr" => "EXR",
            _ => continue,
        };
        if !path.is_file() {
            continue;
        }
        kinds.insert(kind);
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let number = last_number(&stem).ok_or_else(|| {
            Error::parse(
                &path,
                0,
                "a slice file without a number in its name: the number gives the slice order",
            )
        })?;
        found.push((number, path));
    }
    if found.is_empty() {
        return Err(Error::parse(
            dir,
            0,
            "no slice images (.png, .tif, .tiff, .exr) in this directory",
        ));
    }
    if kinds.len() > 1 {
        let list: Vec<&str> = kinds.into_iter().collect();
        return Err(Error::parse(
            dir,
            0,
            format!(
                "slices of several kinds ({}): keep one kind per directory",
                list.join(", ")
            ),
        ));
    }
    found.sort();
    for pair in found.windows(2) {
        if pair[0].0 == pair[1].0 {
            return Err(Error::parse(
                &pair[1].1,
                0,
                format!(
                    "has the same slice number {} as {}",
                    pair[0].0,
                    name(&pair[0].1)
                ),
            ));
        }
    }
    Ok(found.into_iter().map(|(_, p)| p).collect())
}

/// The last run of decimal digits in `s` (`slice_0012_t1` → 12).
fn last_number(s: &str) -> Option<u64> {
    let end = s.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = s[..end]
        .rfind(|c: char| !c.is_ascii_digit())
        .map_or(0, |i| i + 1);
    s[start..end].parse().ok()
}

/// Decodes one slice file (a TIFF may hold several pages).
fn decode_file(path: &Path) -> Result<Vec<Slice>> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "png" => Ok(vec![png_slice(path)?]),
        "exr" => Ok(vec![exr_slice(path)?]),
        _ => tiff_pages(path).map(|(pages, _)| pages),
    }
}

/// The samples a slice file decodes to, from its header alone.
pub(crate) fn file_samples(path: &Path) -> Result<u64> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let header = |kind: &str, e: String| {
        Error::parse(path, 0, format!("cannot read the {kind} header: {e}"))
    };
    match ext.as_str() {
        "png" => {
            crate::io::open_regular(path)?;
            let (w, h) = image::ImageReader::open(path)
                .map_err(|e| Error::io(path, e))?
                .with_guessed_format()
                .map_err(|e| Error::io(path, e))?
                .into_dimensions()
                .map_err(|e| header("PNG", e.to_string()))?;
            Ok(u64::from(w) * u64::from(h))
        }
        "exr" => {
            crate::io::open_regular(path)?;
            let meta = ::exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| header("EXR", e.to_string()))?;
            Ok(meta
                .headers
                .iter()
                .map(|h| {
                    (h.layer_size.0 as u64)
                        .saturating_mul(h.layer_size.1 as u64)
                        .saturating_mul(h.channels.list.len() as u64)
                })
                .fold(0u64, u64::saturating_add))
        }
        _ => tiff_samples(path),
    }
}

/// Refuses (before decoding) a stack of `samples` that would not fit the
/// memory budget: the decoded slices as f32 and the stacked volume they are
/// copied into, 8 bytes a sample.
pub(crate) fn check_decoded(what: &str, samples: u64) -> Result<()> {
    crate::memory::check_memory(what, crate::memory::bytes_of(samples, 8))
}

/// Decodes a PNG: 8/16-bit grey kept as stored; colour converted to luma.
fn png_slice(path: &Path) -> Result<Slice> {
    let bytes = crate::io::read_input(path)?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| Error::parse(path, 0, format!("cannot decode the PNG: {e}")))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (kind, note, samples): (&str, Option<&str>, Vec<f32>) = match img {
        DynamicImage::ImageLuma8(b) => ("8-bit grey", None, to_f32(b.as_raw())),
        DynamicImage::ImageLuma16(b) => ("16-bit grey", None, to_f32(b.as_raw())),
        DynamicImage::ImageLumaA8(_) => (
            "8-bit grey",
            Some("alpha channel of the slices ignored"),
            to_f32(img.to_luma8().as_raw()),
        ),
        DynamicImage::ImageLumaA16(_) => (
            "16-bit grey",
            Some("alpha channel of the slices ignored"),
            to_f32(img.to_luma16().as_raw()),
        ),
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_) => (
            "8-bit grey",
            Some("colour slices converted to grey (Rec. 709 luma)"),
            to_f32(img.to_luma8().as_raw()),
        ),
        DynamicImage::ImageRgb16(_) | DynamicImage::ImageRgba16(_) => (
            "16-bit grey",
            Some("colour slices converted to grey (Rec. 709 luma)"),
            to_f32(img.to_luma16().as_raw()),
        ),
        other => {
            return Err(Error::parse(
                path,
                0,
                format!("unsupported PNG colour type {:?}", other.color()),
            ));
        }
    };
    Ok(Slice {
        width,
        height,
        kind: kind.into(),
        samples,
        note: note.map(str::to_string),
    })
}

/// Integer samples as f32.
fn to_f32<T: Copy + Into<f32>>(v: &[T]) -> Vec<f32> {
    v.iter().map(|&x| x.into()).collect()
}

/// The file name of `path`, for messages.
pub(crate) fn name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_number_in_a_name_orders_slices() {
        assert_eq!(last_number("slice_10"), Some(10));
        assert_eq!(last_number("img007"), Some(7));
        assert_eq!(last_number("t1_slice_12_x"), Some(12));
        assert_eq!(last_number("slice"), None);
    }
}

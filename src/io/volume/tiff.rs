//! TIFF volumes: a multi-page file with one page per z slice (page order =
//! z), or single pages in a slice directory. Grey samples of any integer
//! width or float (the `tiff` crate decodes compression and byte order);
//! colour pages are an error.
//!
//! Spacing comes from the ImageJ description (`unit=mm`, `spacing=<sz>`)
//! with X/YResolution = pixels per unit, as ImageJ / Fiji write it; without
//! an ImageJ description the resolution tags are ignored (they are usually a
//! print resolution such as 72 dpi).

use std::io::BufReader;
use std::path::Path;

use ::tiff::ColorType;
use ::tiff::decoder::ifd::Value;
use ::tiff::decoder::{Decoder, DecodingResult};
use ::tiff::tags::Tag;

use super::decoded::{Decoded, Placement};
use super::slices::{Slice, check_decoded, name, stacked};
use crate::error::{Error, Result};

/// Reads a (multi-page) TIFF file as a volume.
pub(crate) fn read_tiff_stack(path: &Path) -> Result<Decoded> {
    check_decoded(&format!("decoding {}", name(path)), tiff_samples(path)?)?;
    let (pages, spacing) = tiff_pages(path)?;
    let owned = path.to_path_buf();
    let stack = stacked(pages.into_iter().map(|s| (&owned, s)).collect())?;
    Ok(Decoded {
        dims: stack.dims,
        source: format!(
            "TIFF, {} pages ({}), {}",
            stack.dims[2],
            stack.kind,
            name(path)
        ),
        data: stack.data,
        placement: Placement::Grid { spacing },
        notes: stack.notes,
        physical: false,
    })
}

/// The samples of every page of the TIFF at `path`, from the page headers
/// alone (nothing is decoded), for the memory budget before decoding: a
/// small file of many huge pages that share one strip decodes to gigabytes.
pub(crate) fn tiff_samples(path: &Path) -> Result<u64> {
    let bad = |e: ::tiff::TiffError| Error::parse(path, 0, format!("cannot decode the TIFF: {e}"));
    let file = crate::io::open_regular(path)?;
    let mut dec = Decoder::new(BufReader::new(file)).map_err(bad)?;
    let mut total = 0u64;
    loop {
        let (w, h) = dec.dimensions().map_err(bad)?;
        total = total.saturating_add(u64::from(w) * u64::from(h));
        if !dec.more_images() {
            return Ok(total);
        }
        dec.next_image().map_err(bad)?;
    }
}

/// Every page of the TIFF at `path`, and the spacing its ImageJ metadata gives.
pub(crate) fn tiff_pages(path: &Path) -> Result<(Vec<Slice>, Option<[f64; 3]>)> {
    let bad = |e: ::tiff::TiffError| Error::parse(path, 0, format!("cannot decode the TIFF: {e}"));
    let file = crate::io::open_regular(path)?;
    // The tiff crate's default limits (256 MiB per page) turn an absurd page
    // size in a damaged header into an error instead of an allocation failure.
    let mut dec = Decoder::new(BufReader::new(file)).map_err(bad)?;
    let spacing = imagej_spacing(&mut dec);
    let mut pages = Vec::new();
    loop {
        let page = pages.len();
        let (w, h) = dec.dimensions().map_err(bad)?;
        let colour = dec.colortype().map_err(bad)?;
        let ColorType::Gray(bits) = colour else {
            return Err(Error::parse(
                path,
                page,
                format!("page {page} is {colour:?}: only grey-scale TIFF pages are read"),
            ));
        };
        let image = dec.read_image().map_err(bad)?;
        let (kind, samples) = samples_f32(image, bits);
        pages.push(Slice {
            width: w as usize,
            height: h as usize,
            kind,
            samples,
            note: None,
        });
        if !dec.more_images() {
            break;
        }
        dec.next_image().map_err(bad)?;
    }
    Ok((pages, spacing))
}

/// The decoded samples as f32 with a kind label (`16-bit grey`, `32-bit float`).
fn samples_f32(image: DecodingResult, bits: u8) -> (String, Vec<f32>) {
    let grey = |b: u8| format!("{b}-bit grey");
    match image {
        DecodingResult::U8(v) => (grey(bits), v.into_iter().map(f32::from).collect()),
        DecodingResult::U16(v) => (grey(bits), v.into_iter().map(f32::from).collect()),
        DecodingResult::U32(v) => (grey(bits), v.into_iter().map(|x| x as f32).collect()),
        DecodingResult::U64(v) => (grey(bits), v.into_iter().map(|x| x as f32).collect()),
        DecodingResult::I8(v) => (
            format!("{bits}-bit signed"),
            v.into_iter().map(f32::from).collect(),
        ),
        DecodingResult::I16(v) => (
            format!("{bits}-bit signed"),
            v.into_iter().map(f32::from).collect(),
        ),
        DecodingResult::I32(v) => (
            format!("{bits}-bit signed"),
            v.into_iter().map(|x| x as f32).collect(),
        ),
        DecodingResult::I64(v) => (
            format!("{bits}-bit signed"),
            v.into_iter().map(|x| x as f32).collect(),
        ),
        DecodingResult::F16(v) => (
            "16-bit float".into(),
            v.into_iter().map(|x| x.to_f32()).collect(),
        ),
        DecodingResult::F32(v) => ("32-bit float".into(), v),
        DecodingResult::F64(v) => (
            "64-bit float".into(),
            v.into_iter().map(|x| x as f32).collect(),
        ),
    }
}

/// Spacing `[1/XResolution, 1/YResolution, spacing]` in mm from an ImageJ
/// description with a known `unit=` (mm, micron, cm, m, nm); `None` otherwise.
fn imagej_spacing<R: std::io::Read + std::io::Seek>(dec: &mut Decoder<R>) -> Option<[f64; 3]> {
    let Ok(Some(Value::Ascii(text))) = dec.find_tag(Tag::ImageDescription) else {
        return None;
    };
    if !text.starts_with("ImageJ=") {
        return None;
    }
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix('='))
            .map(str::trim)
    };
    let mm_per_unit = match field("unit")? {
        "mm" => 1.0,
        "micron" | "um" | "\u{b5}m" | "\\u00B5m" => 1e-3,
        "nm" => 1e-6,
        "cm" => 10.0,
        "m" | "meter" => 1e3,
        _ => return None,
    };
    let mut per_unit = |tag| match dec.find_tag(tag) {
        Ok(Some(Value::Rational(n, d))) if n > 0 && d > 0 => Some(f64::from(d) / f64::from(n)),
        _ => None,
    };
    let sx = per_unit(Tag::XResolution)?;
    let sy = per_unit(Tag::YResolution)?;
    let sz: f64 = field("spacing")?.parse().ok()?;
    let s = [sx, sy, sz].map(|v| v * mm_per_unit);
    s.iter().all(|v| v.is_finite() && *v > 0.0).then_some(s)
}

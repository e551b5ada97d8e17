//! Slice writers: PNG stacks (8/16-bit), multi-page TIFF (16-bit or f32) and
//! EXR stacks (f32), plus the linear quantisation of the integer formats.
//!
//! Every slice image follows one convention: column = x, row = y (row 0, the
//! first row in the file, is y index 0), and slice (file or page) order = z.
//! Stack files are `slice_0.png`, `slice_1.png`, … `slice_<nz−1>.png`, numbered
//! without zero padding, so a reader must sort them by number, not by name.

use std::io::Cursor;
use std::path::Path;

use anyhow::{Context, Result};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
    WritableImage,
};
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use serde::Serialize;
use tiff::encoder::{Rational, TiffEncoder, colortype};
use tiff::tags::{ResolutionUnit, Tag};

use crate::volume::grid::Grid;
use crate::volume::parallel::thread_count;

/// Stored values to physical intensities: `physical = slope × stored + intercept`
/// (NIfTI's `scl_slope`, `scl_inter`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct IntensityScale {
    /// Physical intensity per stored unit.
    pub slope: f64,
    /// Physical intensity of stored 0.
    pub intercept: f64,
}

impl IntensityScale {
    /// Floating-point formats store physical intensities.
    pub const IDENTITY: IntensityScale = IntensityScale {
        slope: 1.0,
        intercept: 0.0,
    };

    /// The stored value (unrounded) of a physical intensity.
    pub fn stored(&self, physical: f64) -> f64 {
        (physical - self.intercept) / self.slope
    }
}

/// What a writer wrote.
#[derive(Clone, Debug)]
pub struct Written {
    /// Data files, relative to the sidecar's directory, in z order where it matters.
    pub files: Vec<String>,
    /// Stored sample type: `u8`, `u16` or `f32`.
    pub dtype: &'static str,
    /// Stored → physical.
    pub scale: IntensityScale,
}

/// Maps `data` linearly onto `0..=max_stored`: the lowest of the data and
/// `levels` to 0, the highest to `max_stored`, rounding to nearest.
pub fn quantise(data: &[f32], levels: &[f64], max_stored: u16) -> (Vec<u16>, IntensityScale) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in data
        .iter()
        .map(|&v| f64::from(v))
        .chain(levels.iter().copied())
    {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        hi = lo + 1.0;
    }
    let scale = IntensityScale {
        slope: (hi - lo) / f64::from(max_stored),
        intercept: lo,
    };
    let stored = data
        .iter()
        .map(|&v| {
            scale
                .stored(f64::from(v))
                .round()
                .clamp(0.0, f64::from(max_stored)) as u16
        })
        .collect();
    (stored, scale)
}

/// File name of slice `k` of a stack.
pub fn slice_name(k: usize, ext: &str) -> String {
    format!("slice_{k}.{ext}")
}

/// Writes `slice_<k>.png` into `dir` for every z slice, 8 or 16 bits.
pub fn write_png_stack(
    dir: &Path,
    grid: &Grid,
    data: &[f32],
    levels: &[f64],
    bits: u8,
) -> Result<Written> {
    let max = if bits == 8 { u8::MAX as u16 } else { u16::MAX };
    let (stored, scale) = quantise(data, levels, max);
    let [nx, ny, _] = grid.dims;
    let files = write_slices_parallel(dir, grid, "png", |k| {
        let slice = &stored[k * nx * ny..(k + 1) * nx * ny];
        let mut png = Vec::new();
        let encoder =
            PngEncoder::new_with_quality(&mut png, CompressionType::Default, FilterType::Adaptive);
        if bits == 8 {
            let bytes: Vec<u8> = slice.iter().map(|&v| v as u8).collect();
            encoder.write_image(&bytes, nx as u32, ny as u32, image::ExtendedColorType::L8)?;
        } else {
            let bytes: Vec<u8> = slice.iter().flat_map(|v| v.to_ne_bytes()).collect();
            encoder.write_image(&bytes, nx as u32, ny as u32, image::ExtendedColorType::L16)?;
        }
        Ok(png)
    })?;
    Ok(Written {
        files,
        dtype: if bits == 8 { "u8" } else { "u16" },
        scale,
    })
}

/// Writes `slice_<k>.exr` into `dir` for every z slice: one layer with one f32
/// channel named `Y`, lossless ZIP compression.
pub fn write_exr_stack(dir: &Path, grid: &Grid, data: &[f32]) -> Result<Written> {
    let [nx, ny, _] = grid.dims;
    let files = write_slices_parallel(dir, grid, "exr", |k| {
        let slice = data[k * nx * ny..(k + 1) * nx * ny].to_vec();
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            "Y",
            FlatSamples::F32(slice),
        )]));
        let layer = Layer::new(
            (nx, ny),
            LayerAttributes::default(),
            Encoding::SMALL_LOSSLESS,
            channels,
        );
        let mut bytes = Cursor::new(Vec::new());
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_buffered(&mut bytes)
            .map_err(|e| anyhow::anyhow!("encoding EXR slice {k}: {e}"))?;
        Ok(bytes.into_inner())
    })?;
    Ok(Written {
        files,
        dtype: "f32",
        scale: IntensityScale::IDENTITY,
    })
}

/// Encodes every slice with `encode` on several threads and writes
/// `slice_<k>.<ext>` into `dir` (a private staging directory). Returns the file
/// names in z order.
fn write_slices_parallel(
    dir: &Path,
    grid: &Grid,
    ext: &str,
    encode: impl Fn(usize) -> Result<Vec<u8>> + Sync,
) -> Result<Vec<String>> {
    let nz = grid.dims[2];
    let threads = thread_count(nz);
    let results: Vec<Result<()>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let encode = &encode;
                scope.spawn(move || -> Result<()> {
                    for k in (t..nz).step_by(threads) {
                        let bytes = encode(k)?;
                        let path = dir.join(slice_name(k, ext));
                        std::fs::write(&path, bytes)
                            .with_context(|| format!("{}", path.display()))?;
                    }
                    Ok(())
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a slice writer panicked")))
            })
            .collect()
    });
    for r in results {
        r?;
    }
    Ok((0..nz).map(|k| slice_name(k, ext)).collect())
}

/// Encodes a multi-page TIFF, one page per z slice: 16-bit grey (quantised like
/// PNG 16) or 32-bit float. Pages carry X/YResolution = 1/spacing (pixels per
/// mm, ResolutionUnit none) and the first page an ImageJ description (`unit=mm`,
/// `spacing=<sz>`) so that Fiji opens it with the right voxel size.
pub fn tiff_bytes(
    grid: &Grid,
    data: &[f32],
    levels: &[f64],
    float: bool,
) -> Result<(Vec<u8>, Written)> {
    let [nx, ny, nz] = grid.dims;
    let mut bytes = Cursor::new(Vec::new());
    let (lo, hi) = data
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let description = format!(
        "ImageJ=1.54f\nimages={nz}\nslices={nz}\nunit=mm\nspacing={}\nloop=false\nmin={lo}\nmax={hi}\n",
        grid.spacing[2]
    );
    let written;
    {
        let mut tiff = TiffEncoder::new(&mut bytes)?;
        let per_mm = |s: f64| Rational {
            n: 1_000_000,
            d: (s * 1e6).round().clamp(1.0, f64::from(u32::MAX)) as u32,
        };
        macro_rules! page {
            ($colour:ty, $slice:expr, $k:expr) => {{
                let mut page = tiff.new_image::<$colour>(nx as u32, ny as u32)?;
                page.resolution_unit(ResolutionUnit::None);
                page.x_resolution(per_mm(grid.spacing[0]));
                page.y_resolution(per_mm(grid.spacing[1]));
                if $k == 0 {
                    page.encoder()
                        .write_tag(Tag::ImageDescription, description.as_str())?;
                }
                page.write_data($slice)?;
            }};
        }
        if float {
            for k in 0..nz {
                page!(
                    colortype::Gray32Float,
                    &data[k * nx * ny..(k + 1) * nx * ny],
                    k
                );
            }
            written = Written {
                files: Vec::new(),
                dtype: "f32",
                scale: IntensityScale::IDENTITY,
            };
        } else {
            let (stored, scale) = quantise(data, levels, u16::MAX);
            for k in 0..nz {
                page!(
                    colortype::Gray16,
                    &stored[k * nx * ny..(k + 1) * nx * ny],
                    k
                );
            }
            written = Written {
                files: Vec::new(),
                dtype: "u16",
                scale,
            };
        }
    }
    Ok((bytes.into_inner(), written))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantise_maps_the_range_onto_the_integers() {
        let (q, s) = quantise(&[0.0, 0.5, 1.0], &[0.2, 0.8], 255);
        assert_eq!(q, vec![0, 128, 255]);
        assert!((s.slope - 1.0 / 255.0).abs() < 1e-15 && s.intercept == 0.0);
        let (q, s) = quantise(&[2.0, 2.0], &[2.0], 255);
        assert_eq!(q, vec![0, 0]);
        assert_eq!(s.intercept, 2.0);
    }
}

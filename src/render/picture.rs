//! `Picture`: an 8-bit RGB image in memory, and writing it as PNG.

use std::path::Path;

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

use crate::error::{Error, Result};
use crate::io::atomic_write;

/// An 8-bit sRGB colour `[r, g, b]`.
pub type Rgb = [u8; 3];

/// Largest width or height of a picture, in pixels.
pub const MAX_SIDE: u32 = 8192;

/// An RGB picture, row-major from the top-left corner.
///
/// ```
/// use subdyn::render::Picture;
/// let mut p = Picture::new(4, 3, [255, 255, 255]).unwrap();
/// p.set(1, 2, [255, 0, 0]);
/// assert_eq!(p.get(1, 2), Some([255, 0, 0]));
/// assert_eq!(p.get(4, 0), None);
/// assert_eq!(p.count(|c| c != [255, 255, 255]), 1);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Picture {
    width: u32,
    height: u32,
    pixels: Vec<Rgb>,
}

impl Picture {
    /// A picture filled with `background`; each side must be 1 to [`MAX_SIDE`].
    pub fn new(width: u32, height: u32, background: Rgb) -> Result<Picture> {
        check_size(width, height)?;
        Ok(Picture {
            width,
            height,
            pixels: vec![background; width as usize * height as usize],
        })
    }

    /// Builds a picture from row-major pixels.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Rgb>) -> Result<Picture> {
        check_size(width, height)?;
        if pixels.len() != width as usize * height as usize {
            return Err(Error::size_mismatch(format!(
                "{} pixels for a {width}×{height} picture",
                pixels.len()
            )));
        }
        Ok(Picture {
            width,
            height,
            pixels,
        })
    }

    /// The pictures in a row, left to right, top-aligned on a white
    /// background (at least one picture).
    pub fn side_by_side(pictures: &[Picture]) -> Result<Picture> {
        let width = pictures.iter().map(|p| p.width).sum();
        let height = pictures.iter().map(|p| p.height).max().unwrap_or(0);
        let mut strip = Picture::new(width, height, [255, 255, 255])?;
        let mut x0 = 0;
        for p in pictures {
            for (y, row) in p.pixels.chunks(p.width as usize).enumerate() {
                let start = y * width as usize + x0;
                strip.pixels[start..start + row.len()].copy_from_slice(row);
            }
            x0 += p.width as usize;
        }
        Ok(strip)
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, row-major from the top-left corner.
    pub fn pixels(&self) -> &[Rgb] {
        &self.pixels
    }

    /// The pixel in column `x`, row `y` (0 at the top); `None` outside.
    pub fn get(&self, x: u32, y: u32) -> Option<Rgb> {
        (x < self.width && y < self.height)
            .then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Sets a pixel; coordinates outside the picture are ignored.
    pub fn set(&mut self, x: i64, y: i64, color: Rgb) {
        if x >= 0 && y >= 0 && (x as u64) < self.width as u64 && (y as u64) < self.height as u64 {
            self.pixels[y as usize * self.width as usize + x as usize] = color;
        }
    }

    /// Fills the rectangle `[x0, x1) × [y0, y1)` (clipped to the picture).
    pub fn fill_rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, color: Rgb) {
        for y in y0.max(0)..y1.min(self.height as i64) {
            for x in x0.max(0)..x1.min(self.width as i64) {
                self.set(x, y, color);
            }
        }
    }

    /// Number of pixels whose colour satisfies `pred`.
    pub fn count(&self, pred: impl Fn(Rgb) -> bool) -> usize {
        self.pixels.iter().filter(|&&c| pred(c)).count()
    }

    /// The picture encoded as PNG (8-bit RGB, best compression).
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let mut bytes = Vec::new();
        self.encode_png(&mut bytes)
            .map_err(|e| Error::input(format!("cannot encode the PNG: {e}")))?;
        Ok(bytes)
    }

    /// Encodes the picture as PNG into `w`.
    fn encode_png(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        let raw: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        PngEncoder::new_with_quality(w, CompressionType::Best, FilterType::Adaptive)
            .write_image(
                &raw,
                self.width,
                self.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(std::io::Error::other)
    }
}

/// Writes `picture` as a PNG file, atomically: the file appears whole or not
/// at all. The path must end in `.png` (any case).
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// use subdyn::render::{Picture, write_png};
/// let path = dir.path().join("grey.png");
/// write_png(&path, &Picture::new(8, 8, [128, 128, 128])?)?;
/// assert!(path.exists());
/// assert!(write_png(&dir.path().join("grey.jpg"), &Picture::new(8, 8, [0, 0, 0])?).is_err());
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn write_png(path: &Path, picture: &Picture) -> Result<()> {
    check_png_path(path)?;
    atomic_write(path, |w| picture.encode_png(w))
}

/// Fails unless `path` ends in `.png` (any case) and a file can be written
/// there ([`crate::io::check_writable`]).
pub fn check_png_path(path: &Path) -> Result<()> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        crate::io::check_writable(path)
    } else {
        Err(Error::input(format!(
            "{}: pictures are written as PNG; the file name must end in .png",
            path.display()
        )))
    }
}

/// Fails unless both sides are 1 to [`MAX_SIDE`].
pub(crate) fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(Error::out_of_range(format!(
            "picture size {width}×{height} is out of range: each side must be 1 to {MAX_SIDE} pixels"
        )));
    }
    Ok(())
}

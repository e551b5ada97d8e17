//! NIfTI-1 single-file (`.nii`, `.nii.gz`) and raw little-endian f32 encoders.
//!
//! NIfTI-1 layout (nifti1.h): a 348-byte little-endian header, 4 zero bytes
//! (no extension), then the voxels from byte 352 (`vox_offset`), x fastest.
//! Index (i, j, k) maps to world through both the qform (identity quaternion,
//! `pixdim` spacing, `qoffset` origin, `qfac` = 1) and the sform rows
//! `srow_x = (sx, 0, 0, ox)`, `srow_y = (0, sy, 0, oy)`, `srow_z = (0, 0, sz, oz)`,
//! both with code 1 (scanner coordinates), units mm.

use std::io::Write;

use flate2::Compression;
use flate2::write::GzEncoder;

use crate::volume::grid::Grid;

/// `sizeof_hdr` of NIfTI-1.
pub const NIFTI_HEADER_SIZE: usize = 348;
/// Where the voxels start (header + 4-byte extension flag).
pub const NIFTI_VOX_OFFSET: usize = 352;
/// NIfTI datatype code of 32-bit float.
pub const DT_FLOAT32: i16 = 16;
/// `xyzt_units` for millimetres.
pub const NIFTI_UNITS_MM: u8 = 2;

/// The 352 bytes before the voxels of a FLOAT32 NIfTI-1 volume on `grid`
/// (`cal_min`, `cal_max` = the data range).
pub fn nifti_header(grid: &Grid, data_min: f32, data_max: f32) -> Vec<u8> {
    let mut h = vec![0u8; NIFTI_VOX_OFFSET];
    let put_i16 = |h: &mut [u8], at: usize, v: i16| h[at..at + 2].copy_from_slice(&v.to_le_bytes());
    let put_i32 = |h: &mut [u8], at: usize, v: i32| h[at..at + 4].copy_from_slice(&v.to_le_bytes());
    let put_f32 =
        |h: &mut [u8], at: usize, v: f64| h[at..at + 4].copy_from_slice(&(v as f32).to_le_bytes());
    let [sx, sy, sz] = grid.spacing;
    let [ox, oy, oz] = grid.origin;

    put_i32(&mut h, 0, NIFTI_HEADER_SIZE as i32); // sizeof_hdr
    h[38] = b'r'; // regular
    // dim[8]: rank 3, then nx, ny, nz, unused dimensions 1.
    let dims = [3, grid.dims[0], grid.dims[1], grid.dims[2], 1, 1, 1, 1];
    for (n, d) in dims.iter().enumerate() {
        put_i16(&mut h, 40 + 2 * n, *d as i16);
    }
    put_i16(&mut h, 70, DT_FLOAT32); // datatype
    put_i16(&mut h, 72, 32); // bitpix
    // pixdim[8]: qfac, sx, sy, sz, then 1 for time, 0 for the rest.
    for (n, p) in [1.0, sx, sy, sz, 1.0, 0.0, 0.0, 0.0].iter().enumerate() {
        put_f32(&mut h, 76 + 4 * n, *p);
    }
    put_f32(&mut h, 108, NIFTI_VOX_OFFSET as f64); // vox_offset
    put_f32(&mut h, 112, 1.0); // scl_slope
    put_f32(&mut h, 116, 0.0); // scl_inter
    h[123] = NIFTI_UNITS_MM; // xyzt_units
    put_f32(&mut h, 124, f64::from(data_max)); // cal_max
    put_f32(&mut h, 128, f64::from(data_min)); // cal_min
    let descrip = b"subdyn data-gen volume";
    h[148..148 + descrip.len()].copy_from_slice(descrip);
    put_i16(&mut h, 252, 1); // qform_code: scanner
    put_i16(&mut h, 254, 1); // sform_code: scanner
    // quatern_b, c, d = 0 (identity rotation); qoffset = origin.
    put_f32(&mut h, 268, ox);
    put_f32(&mut h, 272, oy);
    put_f32(&mut h, 276, oz);
    let rows = [[sx, 0.0, 0.0, ox], [0.0, sy, 0.0, oy], [0.0, 0.0, sz, oz]];
    for (r, row) in rows.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            put_f32(&mut h, 280 + 16 * r + 4 * c, *v);
        }
    }
    h[344..348].copy_from_slice(b"n+1\0"); // magic
    // Bytes 348..352: extension flag, all zero (no extensions).
    h
}

/// Writes the voxels as little-endian f32.
pub fn write_f32_le(w: &mut dyn Write, data: &[f32]) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in data.chunks(1 << 14) {
        buf.clear();
        for v in chunk {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

/// Writes a complete NIfTI-1 file (header then voxels), gzip-compressed when
/// `gzip` (gzip header with mtime 0, so the bytes depend only on the data).
pub fn write_nifti(
    w: &mut dyn Write,
    grid: &Grid,
    data: &[f32],
    gzip: bool,
) -> std::io::Result<()> {
    let (lo, hi) = data
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let header = nifti_header(grid, lo, hi);
    if gzip {
        let mut gz = GzEncoder::new(w, Compression::default());
        gz.write_all(&header)?;
        write_f32_le(&mut gz, data)?;
        gz.finish()?;
        Ok(())
    } else {
        w.write_all(&header)?;
        write_f32_le(w, data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_fields_sit_at_the_nifti1_offsets() {
        let grid = Grid::new([5, 6, 7], [0.5, 0.75, 2.0], [-1.0, 2.0, 3.5]).unwrap();
        let h = nifti_header(&grid, 0.0, 1.0);
        let i16_at = |at: usize| i16::from_le_bytes([h[at], h[at + 1]]);
        let f32_at = |at: usize| f32::from_le_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]]);
        assert_eq!(i32::from_le_bytes([h[0], h[1], h[2], h[3]]), 348);
        assert_eq!(
            [i16_at(40), i16_at(42), i16_at(44), i16_at(46)],
            [3, 5, 6, 7]
        );
        assert_eq!((i16_at(70), i16_at(72)), (16, 32));
        assert_eq!([f32_at(80), f32_at(84), f32_at(88)], [0.5, 0.75, 2.0]);
        assert_eq!(f32_at(108), 352.0);
        assert_eq!((i16_at(252), i16_at(254)), (1, 1));
        assert_eq!(
            [
                f32_at(280),
                f32_at(292),
                f32_at(300),
                f32_at(308),
                f32_at(320),
                f32_at(324)
            ],
            [0.5, -1.0, 0.75, 2.0, 2.0, 3.5]
        );
        assert_eq!(&h[344..348], b"n+1\0");
        assert_eq!(h.len(), 352);
    }
}

//! The NIfTI-1 header (`nifti1.h`, 348 bytes): dimensions, datatype, byte
//! order, intensity scaling and the voxel-to-world map.
//!
//! The map follows nifti1.h's three methods, in its order of preference:
//! - `sform_code > 0`: `world = S · (i, j, k, 1)ᵀ` with the rows `srow_x`,
//!   `srow_y`, `srow_z` (method 3);
//! - else `qform_code > 0`: `world = R · diag(dx, dy, qfac·dz) · (i, j, k)ᵀ + qoffset`,
//!   `R` the rotation of the unit quaternion `(a, b, c, d)` with
//!   `a = √(1 − b² − c² − d²)` and `qfac = pixdim[0]` (±1) (method 2);
//! - else `world = (i dx, j dy, k dz)` (method 1, ANALYZE compatibility).
//!
//! World coordinates are NIfTI's: RAS+ (x towards the subject's Right, y
//! Anterior, z Superior), in millimetres (metres and microns are converted).

use std::path::Path;

use nalgebra::Matrix3;

use super::samples::SampleType;
use crate::error::{Error, Result};
use crate::math::{Point3, Real};

/// `sizeof_hdr` of NIfTI-1.
pub(crate) const NIFTI1_HEADER_BYTES: usize = 348;
/// `sizeof_hdr` of NIfTI-2 (recognised only to reject it clearly).
const NIFTI2_HEADER_BYTES: i32 = 540;

/// What the header says.
#[derive(Clone, Debug)]
pub(crate) struct NiftiHeader {
    /// Multi-byte fields and voxels are big-endian.
    pub big_endian: bool,
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// Number of 3D volumes (product of `dim[4..=7]`); only the first is read.
    pub volumes: usize,
    /// Stored sample type.
    pub datatype: SampleType,
    /// Byte offset of the first voxel.
    pub vox_offset: u64,
    /// `(scl_slope, scl_inter)` when they change the data.
    pub scaling: Option<(f64, f64)>,
    /// Linear part of the voxel-to-world map, mm.
    pub linear: Matrix3<Real>,
    /// World position of voxel (0, 0, 0), mm.
    pub origin: Point3,
    /// Which method gave the map (for the notes).
    pub method: String,
    /// Remarks for the caller's notes.
    pub notes: Vec<String>,
}

/// Parses the first 348 bytes of a NIfTI-1 file.
pub(crate) fn nifti_header(h: &[u8], path: &Path) -> Result<NiftiHeader> {
    let bad = |m: String| Error::parse(path, 0, m);
    if h.len() < NIFTI1_HEADER_BYTES {
        return Err(bad(format!(
            "{} bytes: too short for a NIfTI-1 header ({NIFTI1_HEADER_BYTES} bytes)",
            h.len()
        )));
    }
    let word = [h[0], h[1], h[2], h[3]];
    let big_endian = match (i32::from_le_bytes(word), i32::from_be_bytes(word)) {
        (348, _) => false,
        (_, 348) => true,
        (NIFTI2_HEADER_BYTES, _) | (_, NIFTI2_HEADER_BYTES) => {
            return Err(bad(
                "a NIfTI-2 header (sizeof_hdr 540); only NIfTI-1 is read — convert it \
                 (e.g. nibabel: nib.Nifti1Image(img.dataobj, img.affine))"
                    .into(),
            ));
        }
        (v, _) => {
            return Err(bad(format!(
                "sizeof_hdr is {v}, not 348: not a NIfTI-1 header"
            )));
        }
    };
    let i16_at = |at: usize| {
        let b = [h[at], h[at + 1]];
        if big_endian {
            i16::from_be_bytes(b)
        } else {
            i16::from_le_bytes(b)
        }
    };
    let f32_at = |at: usize| {
        let b = [h[at], h[at + 1], h[at + 2], h[at + 3]];
        f64::from(if big_endian {
            f32::from_be_bytes(b)
        } else {
            f32::from_le_bytes(b)
        })
    };
    match &h[344..348] {
        b"n+1\0" => {}
        b"ni1\0" => {
            return Err(bad(
                "a two-file NIfTI-1 header (magic 'ni1', .hdr + .img); give a single-file .nii"
                    .into(),
            ));
        }
        m => {
            return Err(bad(format!(
                "no NIfTI-1 magic 'n+1' at byte 344 (found {:?}): an ANALYZE 7.5 file?",
                String::from_utf8_lossy(m)
            )));
        }
    }

    let rank = i16_at(40);
    if !(1..=7).contains(&rank) {
        return Err(bad(format!("dim[0] = {rank}: the rank must be 1 to 7")));
    }
    let mut dim = [1usize; 7];
    for (n, d) in dim.iter_mut().enumerate().take(rank as usize) {
        let v = i16_at(42 + 2 * n);
        if v <= 0 {
            return Err(bad(format!(
                "dim[{}] = {v}: every dimension must be at least 1",
                n + 1
            )));
        }
        *d = v as usize;
    }
    let dims = [dim[0], dim[1], dim[2]];
    let volumes = dim[3..].iter().product();

    let code = i16_at(70);
    let datatype = match code {
        2 => SampleType::U8,
        4 => SampleType::I16,
        8 => SampleType::I32,
        16 => SampleType::F32,
        64 => SampleType::F64,
        256 => SampleType::I8,
        512 => SampleType::U16,
        768 => SampleType::U32,
        1024 => SampleType::I64,
        1280 => SampleType::U64,
        32 | 128 | 1536 | 1792 | 2048 | 2304 => {
            return Err(bad(format!(
                "datatype {code} (complex, RGB or 128-bit float) is not a scalar type subdyn reads"
            )));
        }
        _ => return Err(bad(format!("datatype {code} is not a NIfTI-1 type"))),
    };

    let vox = f32_at(108);
    if !(vox.is_finite() && vox >= NIFTI1_HEADER_BYTES as f64 && vox.fract() == 0.0) {
        return Err(bad(format!(
            "vox_offset {vox} is not a whole byte offset ≥ 348"
        )));
    }
    let mut notes = Vec::new();
    let (slope, inter) = (f32_at(112), f32_at(116));
    let scaling = if slope.is_finite() && slope != 0.0 {
        let inter = if inter.is_finite() { inter } else { 0.0 };
        (slope != 1.0 || inter != 0.0).then(|| {
            notes.push(format!(
                "scl_slope {slope}, scl_inter {inter} applied (values are slope × stored + inter)"
            ));
            (slope, inter)
        })
    } else {
        None
    };
    let unit = match h[123] & 7 {
        1 => {
            notes.push("spatial units metres: converted to mm".into());
            1000.0
        }
        3 => {
            notes.push("spatial units microns: converted to mm".into());
            0.001
        }
        2 => 1.0,
        _ => {
            notes.push("spatial units not given: mm assumed".into());
            1.0
        }
    };

    let pixdim = [0, 1, 2, 3].map(|n| f32_at(76 + 4 * n));
    let (qform, sform) = (i16_at(252), i16_at(254));
    let (linear, origin, method) = if sform > 0 {
        let row = |r: usize| [0, 1, 2, 3].map(|c| f32_at(280 + 16 * r + 4 * c));
        let rows = [row(0), row(1), row(2)];
        let linear = Matrix3::from_fn(|r, c| rows[r][c]);
        let origin = Point3::new(rows[0][3], rows[1][3], rows[2][3]);
        (linear, origin, format!("sform (sform_code {sform})"))
    } else {
        let spacing = [1, 2, 3].map(|n| pixdim[n]);
        for (n, s) in spacing.iter().enumerate() {
            if !(s.is_finite() && *s != 0.0) {
                return Err(bad(format!(
                    "pixdim[{}] = {s}: voxel sizes must be non-zero numbers",
                    n + 1
                )));
            }
        }
        if spacing.iter().any(|s| *s < 0.0) {
            notes.push("negative pixdim: its absolute value used".into());
        }
        let [dx, dy, dz] = spacing.map(f64::abs);
        if qform > 0 {
            let qfac = if pixdim[0] < 0.0 { -1.0 } else { 1.0 };
            let r = quaternion_rotation(f32_at(256), f32_at(260), f32_at(264));
            let linear = r * Matrix3::from_diagonal(&nalgebra::Vector3::new(dx, dy, qfac * dz));
            let origin = Point3::new(f32_at(268), f32_at(272), f32_at(276));
            (linear, origin, format!("qform (qform_code {qform})"))
        } else {
            notes.push("no qform or sform: world = index × pixdim (origin 0)".into());
            let linear = Matrix3::from_diagonal(&nalgebra::Vector3::new(dx, dy, dz));
            (linear, Point3::origin(), "pixdim only".into())
        }
    };
    Ok(NiftiHeader {
        big_endian,
        dims,
        volumes,
        datatype,
        vox_offset: vox as u64,
        scaling,
        linear: linear * unit,
        origin: origin * unit,
        method,
        notes,
    })
}

/// The rotation of the unit quaternion `(a, b, c, d)`, `a = √(1 − b² − c² − d²)`
/// (nifti1.h, "METHOD 2"); when rounding makes `b² + c² + d²` exceed 1,
/// `(b, c, d)` is normalised and `a = 0` (a 180° rotation), as nifti1_io does.
pub(crate) fn quaternion_rotation(b: f64, c: f64, d: f64) -> Matrix3<Real> {
    let s = b * b + c * c + d * d;
    let (a, b, c, d) = if s > 1.0 {
        let n = s.sqrt();
        (0.0, b / n, c / n, d / n)
    } else {
        ((1.0 - s).sqrt(), b, c, d)
    };
    Matrix3::new(
        a * a + b * b - c * c - d * d,
        2.0 * (b * c - a * d),
        2.0 * (b * d + a * c),
        2.0 * (b * c + a * d),
        a * a + c * c - b * b - d * d,
        2.0 * (c * d - a * b),
        2.0 * (b * d - a * c),
        2.0 * (c * d + a * b),
        a * a + d * d - c * c - b * b,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_rotation_is_orthonormal_and_turns_about_z() {
        // 90° about z: (a, b, c, d) = (cos 45°, 0, 0, sin 45°).
        let r = quaternion_rotation(0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2);
        let x = r * nalgebra::Vector3::x();
        assert!((x - nalgebra::Vector3::y()).norm() < 1e-12, "{x}");
        let r = quaternion_rotation(0.3, -0.2, 0.5);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
}

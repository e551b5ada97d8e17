//! `write_scan_ply`: a binary little-endian PLY with `x y z`, optional
//! `nx ny nz` and an `int view` per point. subdyn's own writer has no extra
//! properties; its reader skips them.

use std::io::Write;
use std::path::Path;

use anyhow::Result;
use flate2::Compression;
use flate2::write::GzEncoder;

use super::simulate::Scan;

/// Floating-point type of coordinates and normals in the PLY.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Precision {
    /// 32-bit `float` (half the size; rounding ~6e-8 relative).
    F32,
    /// 64-bit `double` (exact).
    F64,
}

impl Precision {
    /// The PLY type name.
    pub fn ply_name(self) -> &'static str {
        match self {
            Precision::F32 => "float",
            Precision::F64 => "double",
        }
    }
}

/// The vertex properties written, in order, as `(type, name)`.
pub fn properties(precision: Precision, normals: bool) -> Vec<(&'static str, &'static str)> {
    let t = precision.ply_name();
    let mut props = vec![(t, "x"), (t, "y"), (t, "z")];
    if normals {
        props.extend([(t, "nx"), (t, "ny"), (t, "nz")]);
    }
    props.push(("int", "view"));
    props
}

/// Writes `scan` to `path` atomically (gzip-compressed when the name ends in `.gz`).
pub fn write_scan_ply(path: &Path, scan: &Scan, precision: Precision, comment: &str) -> Result<()> {
    let normals = !scan.normals.is_empty();
    let mut bytes = Vec::with_capacity(256 + scan.positions.len() * 52);
    writeln!(bytes, "ply\nformat binary_little_endian 1.0")?;
    writeln!(bytes, "comment {}", comment.replace(['\n', '\r'], " "))?;
    writeln!(bytes, "element vertex {}", scan.positions.len())?;
    for (t, name) in properties(precision, normals) {
        writeln!(bytes, "property {t} {name}")?;
    }
    writeln!(bytes, "end_header")?;
    let put = |x: f64, bytes: &mut Vec<u8>| match precision {
        Precision::F32 => bytes.extend_from_slice(&(x as f32).to_le_bytes()),
        Precision::F64 => bytes.extend_from_slice(&x.to_le_bytes()),
    };
    for (i, p) in scan.positions.iter().enumerate() {
        for c in [p.x, p.y, p.z] {
            put(c, &mut bytes);
        }
        if normals {
            let n = scan.normals[i];
            for c in [n.x, n.y, n.z] {
                put(c, &mut bytes);
            }
        }
        bytes.extend_from_slice(&(scan.views[i] as i32).to_le_bytes());
    }
    let gzip = path
        .file_name()
        .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase().ends_with(".gz"));
    subdyn::io::atomic_write(path, |w| {
        if gzip {
            let mut encoder = GzEncoder::new(w, Compression::best());
            encoder.write_all(&bytes)?;
            encoder.finish()?;
            Ok(())
        } else {
            w.write_all(&bytes)
        }
    })?;
    Ok(())
}

//! XYZ point files: one point per line, `x y z` or `x y z nx ny nz`, columns
//! separated by whitespace or commas, `#` comments and blank lines skipped.

use std::io::Write;
use std::path::Path;

use super::raw::RawGeometry;
use super::text::{content_lines, finite_normal, finite_point, parse_real};
use super::write::{Geometry, write_point_line};
use crate::error::{Error, Result};

/// Parses XYZ text. Every line must have the same number of columns, 3 or 6.
pub(crate) fn parse_xyz(bytes: &[u8], path: &Path) -> Result<RawGeometry> {
    let mut raw = RawGeometry::new();
    let mut normals = Vec::new();
    let mut width: Option<(usize, usize)> = None; // (columns, first line)
    for item in content_lines(bytes, path) {
        let (line, text) = item?;
        let mut columns = [""; 6];
        let mut count = 0;
        for token in text
            .split(|c: char| c.is_ascii_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
        {
            if let Some(slot) = columns.get_mut(count) {
                *slot = token;
            }
            count += 1;
        }
        if count != 3 && count != 6 {
            return Err(Error::parse(
                path,
                line,
                format!("expected 3 or 6 columns (x y z [nx ny nz]), found {count}"),
            ));
        }
        match width {
            None => width = Some((count, line)),
            Some((w, first)) if w != count => {
                return Err(Error::parse(
                    path,
                    line,
                    format!("{count} columns here, but line {first} has {w}"),
                ));
            }
            Some(_) => {}
        }
        let mut values = [0.0; 6];
        for (value, token) in values.iter_mut().zip(&columns[..count]) {
            *value = parse_real(path, line, token, "a coordinate")?;
        }
        let vertex = raw.positions.len();
        raw.positions.push(finite_point(
            path,
            line,
            vertex,
            [values[0], values[1], values[2]],
        )?);
        if count == 6 {
            normals.push(finite_normal(
                path,
                line,
                vertex,
                [values[3], values[4], values[5]],
            )?);
        }
    }
    if width.is_some_and(|(w, _)| w == 6) {
        raw.normals = Some(normals);
    }
    Ok(raw)
}

/// Writes one point per line, with its normal when there are normals.
pub(crate) fn write_xyz(w: &mut dyn Write, geometry: &Geometry) -> std::io::Result<()> {
    for (i, p) in geometry.positions.iter().enumerate() {
        write_point_line(w, p, geometry.normals.and_then(|n| n.get(i)))?;
    }
    Ok(())
}

//! Crease lists: one sharp edge per line, `i j s`.

use std::path::Path;

use super::source::read_input;
use super::text::{content_lines, parse_count, parse_real};
use crate::error::{Error, Result};
use crate::math::Real;

/// Reads a crease list: one crease per line `i j s`, the edge between vertices
/// `i` and `j` (0-based) with sharpness `s ≥ 0` (`inf` for an infinitely sharp
/// crease). `#` comments and blank lines are skipped, so a file of comments
/// only (or an empty file) is an empty list.
///
/// Errors name the file and the line: a wrong number of columns, a non-integer
/// index, `i == j`, a negative or NaN sharpness. Whether `i`–`j` is an edge of
/// the mesh is for the caller to check.
///
/// ```no_run
/// let creases = subdyn::io::read_creases("cube.creases")?;
/// for (i, j, s) in creases {
///     println!("edge {i}-{j}: sharpness {s}");
/// }
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn read_creases(path: impl AsRef<Path>) -> Result<Vec<(u32, u32, Real)>> {
    let path = path.as_ref();
    let bytes = read_input(path)?;
    let mut creases = Vec::new();
    for item in content_lines(&bytes, path) {
        let (line, text) = item?;
        let mut tokens = text.split_ascii_whitespace();
        let (Some(i), Some(j), Some(s), None) =
            (tokens.next(), tokens.next(), tokens.next(), tokens.next())
        else {
            let found = text.split_ascii_whitespace().count();
            return Err(Error::parse(
                path,
                line,
                format!("expected 3 columns `i j sharpness`, found {found}"),
            ));
        };
        let i = vertex_index(path, line, i)?;
        let j = vertex_index(path, line, j)?;
        if i == j {
            return Err(Error::parse(
                path,
                line,
                format!("a crease needs two different vertices, found {i} twice"),
            ));
        }
        let s = parse_real(path, line, s, "the sharpness")?;
        if s.is_nan() || s < 0.0 {
            return Err(Error::parse(
                path,
                line,
                format!("sharpness must be ≥ 0 (or inf), found {s}"),
            ));
        }
        creases.push((i, j, s));
    }
    Ok(creases)
}

/// A 0-based vertex index that fits in `u32`.
fn vertex_index(path: &Path, line: usize, token: &str) -> Result<u32> {
    let index = parse_count(path, line, token, "a vertex index")?;
    u32::try_from(index)
        .map_err(|_| Error::parse(path, line, format!("vertex index {index} is too large")))
}

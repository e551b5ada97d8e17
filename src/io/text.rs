//! Helpers shared by the readers: numbered content lines for the line-oriented
//! text formats (OBJ, OFF, XYZ, crease lists), number parsing whose errors name
//! the line, and the finiteness checks every reader applies to coordinates.

use std::path::Path;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

/// The lines of `bytes` that carry content, as `(line_number, text)`: a line
/// ends at `\n`, `\r\n` or a lone `\r` (old Mac files), numbers are 1-based,
/// `#` comments are cut off, ASCII whitespace is trimmed and lines left blank
/// are skipped. A line that is not UTF-8 once its comment is cut off is an
/// error naming the line.
pub(crate) fn content_lines<'a>(
    bytes: &'a [u8],
    path: &'a Path,
) -> impl Iterator<Item = Result<(usize, &'a str)>> + 'a {
    let mut rest = Some(bytes);
    std::iter::from_fn(move || {
        let text = rest?;
        match text.iter().position(|&b| b == b'\n' || b == b'\r') {
            Some(k) => {
                let end = if text[k] == b'\r' && text.get(k + 1) == Some(&b'\n') {
                    k + 2
                } else {
                    k + 1
                };
                rest = Some(&text[end..]);
                Some(&text[..k])
            }
            None => {
                rest = None;
                Some(text)
            }
        }
    })
    .enumerate()
    .filter_map(move |(i, raw)| {
        let raw = match raw.iter().position(|&b| b == b'#') {
            Some(k) => &raw[..k],
            None => raw,
        };
        let raw = raw.trim_ascii();
        if raw.is_empty() {
            return None;
        }
        Some(
            std::str::from_utf8(raw)
                .map(|s| (i + 1, s))
                .map_err(|_| Error::parse(path, i + 1, "the line is not valid UTF-8 text")),
        )
    })
}

/// Parses one number (`inf` and `nan` are accepted here and rejected by the
/// finiteness checks, so that their error can name the vertex).
pub(crate) fn parse_real(path: &Path, line: usize, token: &str, what: &str) -> Result<Real> {
    token.parse::<Real>().map_err(|_| {
        Error::parse(
            path,
            line,
            format!("expected a number for {what}, found `{token}`"),
        )
    })
}

/// Parses the next three tokens as numbers; fewer than three is an error.
pub(crate) fn parse_triple<'a>(
    path: &Path,
    line: usize,
    tokens: &mut impl Iterator<Item = &'a str>,
    what: &str,
) -> Result<[Real; 3]> {
    let mut out = [0.0; 3];
    for (k, slot) in out.iter_mut().enumerate() {
        let token = tokens.next().ok_or_else(|| {
            Error::parse(
                path,
                line,
                format!("expected 3 numbers for {what}, found {k}"),
            )
        })?;
        *slot = parse_real(path, line, token, what)?;
    }
    Ok(out)
}

/// Parses a count or a 0-based index: a non-negative integer.
pub(crate) fn parse_count(path: &Path, line: usize, token: &str, what: &str) -> Result<usize> {
    token.parse::<usize>().map_err(|_| {
        Error::parse(
            path,
            line,
            format!("expected a non-negative integer for {what}, found `{token}`"),
        )
    })
}

/// The position of vertex `vertex` (0-based), rejecting NaN and infinities with
/// an error that names the vertex and, through `line`, where it was read.
pub(crate) fn finite_point(
    path: &Path,
    line: usize,
    vertex: usize,
    c: [Real; 3],
) -> Result<Point3> {
    if c.iter().all(|v| v.is_finite()) {
        Ok(Point3::new(c[0], c[1], c[2]))
    } else {
        Err(Error::parse(
            path,
            line,
            format!(
                "vertex {vertex} has a non-finite coordinate ({}, {}, {})",
                c[0], c[1], c[2]
            ),
        ))
    }
}

/// The normal of vertex `vertex`, rejecting NaN and infinities like [`finite_point`].
pub(crate) fn finite_normal(
    path: &Path,
    line: usize,
    vertex: usize,
    c: [Real; 3],
) -> Result<Vector3> {
    if c.iter().all(|v| v.is_finite()) {
        Ok(Vector3::new(c[0], c[1], c[2]))
    } else {
        Err(Error::parse(
            path,
            line,
            format!(
                "vertex {vertex} has a non-finite normal ({}, {}, {})",
                c[0], c[1], c[2]
            ),
        ))
    }
}

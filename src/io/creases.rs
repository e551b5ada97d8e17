//! Subdivision tags: sharp edges, sharp vertices and holes, from a tag file
//! (`i j s`, `v i s`, `h f` lines) or from the `t` lines of an OBJ file
//! (OpenSubdiv's tag syntax, as in its regression shapes).

use std::path::Path;

use super::atomic::atomic_write;
use super::source::read_input;
use super::text::{content_lines, parse_count, parse_real};
use super::write::write_real;
use crate::error::{Error, Result};
use crate::math::Real;
use crate::subdivision::{BoundaryRule, RefineOptions, TriangleRule};
use crate::topology::CreaseMethod;

/// Sharp edges, sharp vertices and hole faces of a mesh (0-based indices).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SubdivisionTags {
    /// `(i, j, s)`: the edge between vertices `i` and `j` has sharpness `s`.
    pub creases: Vec<(u32, u32, Real)>,
    /// `(v, s)`: vertex `v` has sharpness `s`.
    pub corners: Vec<(u32, Real)>,
    /// Faces that are holes.
    pub holes: Vec<u32>,
}

impl SubdivisionTags {
    /// Adds these tags to `options`.
    pub fn add_to(self, options: &mut RefineOptions) {
        options.creases.extend(self.creases);
        options.corners.extend(self.corners);
        options.holes.extend(self.holes);
    }
}

/// The tags of an OBJ file's `t` lines, with the scheme options they set.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjTags {
    /// Creases, corners and holes.
    pub tags: SubdivisionTags,
    /// `t interpolateboundary 1/0/0 N` (0 none, 1 edge-and-corner, 2 edge-only).
    pub boundary: Option<BoundaryRule>,
    /// `t creasemethod 0/0/1 chaikin|normal|uniform`.
    pub crease_method: Option<CreaseMethod>,
    /// `t smoothtriangles 0/0/1 smooth|catmark`.
    pub triangles: Option<TriangleRule>,
    /// Names of the tags read but not applied (face-varying and hierarchical
    /// edits), once each, in the order met.
    pub ignored: Vec<String>,
}

impl ObjTags {
    /// `base` with these tags added and the scheme options they set.
    pub fn apply(self, mut base: RefineOptions) -> RefineOptions {
        self.tags.add_to(&mut base);
        if let Some(b) = self.boundary {
            base.boundary = b;
        }
        if let Some(m) = self.crease_method {
            base.crease_method = m;
        }
        if let Some(t) = self.triangles {
            base.triangles = t;
        }
        base
    }
}

/// Reads a tag file. Each line is one of
///
/// - `i j s`: the edge between vertices `i` and `j` has sharpness `s`;
/// - `v i s`: vertex `i` has sharpness `s` (a corner while it lasts);
/// - `h f`: face `f` is a hole;
///
/// with 0-based indices, `s ≥ 0` and `inf` (or any `s ≥ 10`) infinitely
/// sharp. `#` comments and blank lines are skipped, so a file of comments
/// only (or an empty file) has no tags.
///
/// Errors name the file and the line: a wrong number of columns, a
/// non-integer index, `i == j`, a negative or NaN sharpness. Whether the
/// indices are in the mesh is for the caller to check.
///
/// ```no_run
/// let tags = subdyn::io::read_tags("cube.creases")?;
/// for (i, j, s) in tags.creases {
///     println!("edge {i}-{j}: sharpness {s}");
/// }
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn read_tags(path: impl AsRef<Path>) -> Result<SubdivisionTags> {
    let path = path.as_ref();
    let bytes = read_input(path)?;
    let mut tags = SubdivisionTags::default();
    for item in content_lines(&bytes, path) {
        let (line, text) = item?;
        let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        match tokens.as_slice() {
            ["v", i, s] => {
                let i = index(path, line, i, "a vertex index")?;
                tags.corners.push((i, sharpness(path, line, s)?));
            }
            ["h", f] => tags.holes.push(index(path, line, f, "a face index")?),
            [i, j, s] if !["v", "h"].contains(i) => {
                let (i, j) = (
                    index(path, line, i, "a vertex index")?,
                    index(path, line, j, "a vertex index")?,
                );
                if i == j {
                    return Err(Error::parse(
                        path,
                        line,
                        format!("a crease needs two different vertices, found {i} twice"),
                    ));
                }
                tags.creases.push((i, j, sharpness(path, line, s)?));
            }
            _ => {
                return Err(Error::parse(
                    path,
                    line,
                    format!(
                        "expected `i j sharpness`, `v i sharpness` or `h face`, found {} columns",
                        tokens.len()
                    ),
                ));
            }
        }
    }
    Ok(tags)
}

/// The `t` lines of OBJ text ([`read_obj_tags`]).
pub(crate) fn parse_obj_tags(bytes: &[u8], path: &Path) -> Result<ObjTags> {
    let mut out = ObjTags::default();
    for item in content_lines(bytes, path) {
        let (line, text) = item?;
        let mut tokens = text.split_ascii_whitespace();
        if tokens.next() != Some("t") {
            continue;
        }
        let bad = |msg: String| Error::parse(path, line, msg);
        let name = tokens
            .next()
            .ok_or_else(|| bad("a `t` line needs a tag name".into()))?;
        let counts = tokens.next().ok_or_else(|| {
            bad(format!(
                "tag `{name}` needs its counts `ints/floats/strings`"
            ))
        })?;
        let counts: Vec<usize> = counts
            .split('/')
            .map(|c| parse_count(path, line, c, "a tag count"))
            .collect::<Result<_>>()?;
        let [ni, nf, ns] = counts[..] else {
            return Err(bad(format!(
                "tag `{name}`: expected counts `ints/floats/strings`, found {} numbers",
                counts.len()
            )));
        };
        let rest: Vec<&str> = tokens.collect();
        if rest.len() != ni + nf + ns {
            return Err(bad(format!(
                "tag `{name}` announces {ni} ints, {nf} floats and {ns} strings but has {} values",
                rest.len()
            )));
        }
        let ints = rest[..ni]
            .iter()
            .map(|t| index(path, line, t, "an index"))
            .collect::<Result<Vec<u32>>>()?;
        let floats = rest[ni..ni + nf]
            .iter()
            .map(|t| sharpness(path, line, t))
            .collect::<Result<Vec<Real>>>()?;
        let strings = &rest[ni + nf..];
        // One value for all items, or one per item.
        let value = |k: usize, items: usize| -> Result<Real> {
            match floats.len() {
                1 => Ok(floats[0]),
                n if n == items => Ok(floats[k]),
                n => Err(bad(format!(
                    "tag `{name}` has {items} items and {n} sharpness values: expected 1 or {items}"
                ))),
            }
        };
        match name {
            "crease" => {
                if ints.len() < 2 {
                    return Err(bad("tag `crease` needs at least two vertices".into()));
                }
                for k in 0..ints.len() - 1 {
                    let (i, j) = (ints[k], ints[k + 1]);
                    out.tags.creases.push((i, j, value(k, ints.len() - 1)?));
                }
            }
            "corner" => {
                for (k, &v) in ints.iter().enumerate() {
                    out.tags.corners.push((v, value(k, ints.len())?));
                }
            }
            "hole" => out.tags.holes.extend(&ints),
            "interpolateboundary" => {
                out.boundary = Some(match ints.as_slice() {
                    [0] => BoundaryRule::None,
                    [1] => BoundaryRule::EdgeAndCorner,
                    [2] => BoundaryRule::EdgeOnly,
                    _ => return Err(bad("tag `interpolateboundary` takes one of 0, 1, 2".into())),
                })
            }
            "creasemethod" => {
                out.crease_method = Some(match strings {
                    ["chaikin"] => CreaseMethod::Chaikin,
                    ["normal"] | ["uniform"] => CreaseMethod::Uniform,
                    _ => return Err(bad("tag `creasemethod` takes chaikin or normal".into())),
                })
            }
            "smoothtriangles" => {
                out.triangles = Some(match strings {
                    ["smooth"] => TriangleRule::Smooth,
                    ["catmark"] => TriangleRule::Catmark,
                    _ => return Err(bad("tag `smoothtriangles` takes smooth or catmark".into())),
                })
            }
            other => {
                if !out.ignored.iter().any(|n| n == other) {
                    out.ignored.push(other.to_string());
                }
            }
        }
    }
    Ok(out)
}

/// Reads the `t` lines of an OBJ file, in OpenSubdiv's syntax `t name
/// ni/nf/ns ints… floats… strings…`: `crease` (a chain of vertices, one
/// sharpness or one per edge), `corner` (vertices, one sharpness or one per
/// vertex), `hole` (faces), `interpolateboundary`, `creasemethod`,
/// `smoothtriangles`; other tags are listed in [`ObjTags::ignored`]. Indices
/// are 0-based, as OpenSubdiv writes them. A file without `t` lines has none.
pub fn read_obj_tags(path: impl AsRef<Path>) -> Result<ObjTags> {
    let path = path.as_ref();
    parse_obj_tags(&read_input(path)?, path)
}

/// Writes `tags` as a tag file that [`read_tags`] reads back: a comment
/// line, then `i j s` per crease, `v i s` per corner and `h f` per hole
/// (0-based), atomically.
pub fn write_tags(path: impl AsRef<Path>, tags: &SubdivisionTags) -> Result<()> {
    atomic_write(path.as_ref(), |w| {
        writeln!(
            w,
            "# subdivision tags written by subdyn: i j s (crease), v i s (corner), h f (hole); 0-based, s >= 10 infinitely sharp"
        )?;
        for &(i, j, s) in &tags.creases {
            write!(w, "{i} {j} ")?;
            write_real(w, s)?;
            writeln!(w)?;
        }
        for &(v, s) in &tags.corners {
            write!(w, "v {v} ")?;
            write_real(w, s)?;
            writeln!(w)?;
        }
        for &f in &tags.holes {
            writeln!(w, "h {f}")?;
        }
        Ok(())
    })
}

/// A sharpness `s ≥ 0` (or `inf`).
fn sharpness(path: &Path, line: usize, token: &str) -> Result<Real> {
    let s = parse_real(path, line, token, "the sharpness")?;
    if s.is_nan() || s < 0.0 {
        return Err(Error::parse(
            path,
            line,
            format!("sharpness must be ≥ 0 (or inf), found {s}"),
        ));
    }
    Ok(s)
}

/// A 0-based index that fits in `u32`.
fn index(path: &Path, line: usize, token: &str, what: &str) -> Result<u32> {
    let index = parse_count(path, line, token, what)?;
    u32::try_from(index)
        .map_err(|_| Error::parse(path, line, format!("index {index} is too large")))
}

//! The PLY header: format, elements and their properties, parsed in full.

use std::path::Path;

use crate::error::{Error, Result};

/// How the body after `end_header` is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// Whitespace-separated numbers.
    Ascii,
    /// Packed binary, least significant byte first.
    BinaryLittleEndian,
    /// Packed binary, most significant byte first.
    BinaryBigEndian,
}

/// A PLY scalar type (the names and their `int8 … float64` aliases).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    /// `char`, `int8`.
    I8,
    /// `uchar`, `uint8`.
    U8,
    /// `short`, `int16`.
    I16,
    /// `ushort`, `uint16`.
    U16,
    /// `int`, `int32`.
    I32,
    /// `uint`, `uint32`.
    U32,
    /// `float`, `float32`.
    F32,
    /// `double`, `float64`.
    F64,
}

impl Scalar {
    /// The type called `name` in a header.
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    pub fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

/// One property of an element.
#[derive(Clone, Debug)]
pub(crate) struct Property {
    /// Its name (`x`, `vertex_indices`, …).
    pub name: String,
    /// Its shape and types.
    pub kind: PropertyKind,
}

/// A single value or a counted list of values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PropertyKind {
    /// One value.
    Scalar(Scalar),
    /// A count, then that many items.
    List {
        /// Type of the count.
        count: Scalar,
        /// Type of each item.
        item: Scalar,
    },
}

/// One `element name count` declaration and its properties.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    /// Its name (`vertex`, `face`, `range_grid`, …).
    pub name: String,
    /// How many items the body holds.
    pub count: usize,
    /// Its properties, in body order.
    pub properties: Vec<Property>,
    /// The header line that declared it, for error messages.
    pub line: usize,
}

impl Element {
    /// Bytes per item in a binary body, when no property is a list.
    pub fn fixed_size(&self) -> Option<usize> {
        self.properties.iter().try_fold(0, |sum, p| match p.kind {
            PropertyKind::Scalar(t) => Some(sum + t.size()),
            PropertyKind::List { .. } => None,
        })
    }

    /// The property called `name`.
    pub fn property(&self, name: &str) -> Option<(usize, &Property)> {
        self.properties
            .iter()
            .enumerate()
            .find(|(_, p)| p.name == name)
    }
}

/// A parsed header.
#[derive(Debug)]
pub(crate) struct Header {
    /// Body encoding.
    pub encoding: Encoding,
    /// Elements in body order.
    pub elements: Vec<Element>,
    /// Byte offset of the body (just after the `end_header` line).
    pub body_start: usize,
    /// Number of header lines, so that ASCII body lines can be numbered.
    pub header_lines: usize,
}

/// Parses the header at the start of `bytes`: `ply`, `format`, `element`,
/// `property` and `end_header` lines; `comment` and `obj_info` lines skipped.
pub(crate) fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut pos = 0;
    let mut line = 0;
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(Error::parse(
                path,
                line,
                "the header has no `end_header` line",
            ));
        };
        let raw = bytes[pos..pos + len].trim_ascii();
        pos += len + 1;
        line += 1;
        if line == 1 {
            if raw != b"ply" {
                return Err(Error::parse(
                    path,
                    1,
                    "not a PLY file: the first line must be `ply`",
                ));
            }
            continue;
        }
        if raw.is_empty() || raw.starts_with(b"comment") || raw.starts_with(b"obj_info") {
            continue;
        }
        let text = std::str::from_utf8(raw)
            .map_err(|_| Error::parse(path, line, "the header line is not valid text"))?;
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        match words[..] {
            ["end_header"] => break,
            ["format", name, _version] => {
                encoding = Some(match name {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    other => {
                        return Err(Error::parse(
                            path,
                            line,
                            format!(
                                "unknown PLY format `{other}`; expected ascii, \
                                 binary_little_endian or binary_big_endian"
                            ),
                        ));
                    }
                });
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| {
                    Error::parse(path, line, format!("element `{name}`: bad count `{count}`"))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                    line,
                });
            }
            ["property", ..] => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| Error::parse(path, line, "a property before any element"))?;
                element.properties.push(property(path, line, &words[1..])?);
            }
            _ => {
                return Err(Error::parse(
                    path,
                    line,
                    format!("unexpected header line `{text}`"),
                ));
            }
        }
    }
    let encoding =
        encoding.ok_or_else(|| Error::parse(path, line, "the header has no `format` line"))?;
    Ok(Header {
        encoding,
        elements,
        body_start: pos,
        header_lines: line,
    })
}

/// Parses the words after `property`: `type name` or `list count_type item_type name`.
fn property(path: &Path, line: usize, words: &[&str]) -> Result<Property> {
    let scalar = |name: &str| {
        Scalar::from_name(name)
            .ok_or_else(|| Error::parse(path, line, format!("unknown property type `{name}`")))
    };
    match *words {
        ["list", count, item, name] => Ok(Property {
            name: name.to_string(),
            kind: PropertyKind::List {
                count: scalar(count)?,
                item: scalar(item)?,
            },
        }),
        [ty, name] if ty != "list" => Ok(Property {
            name: name.to_string(),
            kind: PropertyKind::Scalar(scalar(ty)?),
        }),
        _ => Err(Error::parse(
            path,
            line,
            "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
        )),
    }
}

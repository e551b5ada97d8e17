//! The values of a PLY body, one at a time, from ASCII tokens or packed
//! binary in either byte order — the one difference between the encodings.

use super::header::Scalar;

/// Why a value could not be read.
#[derive(Debug)]
pub(crate) enum Fail {
    /// The body ended.
    End,
    /// An ASCII token that is not a number (the token itself).
    Bad(String),
}

/// A stream of body values.
pub(crate) trait Values {
    /// True for binary bodies, whose fixed-size items can be skipped at once.
    const BINARY: bool;

    /// The next value, converted to `f64` (exact for every PLY integer type).
    fn value(&mut self, ty: Scalar) -> Result<f64, Fail>;

    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail>;

    /// Bytes not yet consumed.
    fn remaining(&self) -> usize;

    /// Where item `item` of the current element is, for `Error::Parse::line`:
    /// the current line of an ASCII body, the 0-based item index in a binary one.
    fn location(&self, item: usize) -> usize;

    /// A description of data left after the last element, if there is any.
    fn leftover(&mut self) -> Option<String>;
}

/// Whitespace-separated tokens of an ASCII body, with line numbers.
pub(crate) struct AsciiValues<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> AsciiValues<'a> {
    /// Reads `data`, whose first line is line `first_line` of the file.
    pub fn new(data: &'a [u8], first_line: usize) -> Self {
        AsciiValues {
            data,
            pos: 0,
            line: first_line,
        }
    }

    /// The next token, counting the newlines skipped before it. At the end of
    /// the data the line stays that of the last token.
    fn token(&mut self) -> Option<&'a [u8]> {
        let line = self.line;
        while let Some(&b) = self.data.get(self.pos) {
            if b == b'\n' {
                self.line += 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if self.pos == start {
            self.line = line;
            return None;
        }
        Some(&self.data[start..self.pos])
    }
}

impl Values for AsciiValues<'_> {
    const BINARY: bool = false;

    fn value(&mut self, _ty: Scalar) -> Result<f64, Fail> {
        let token = self.token().ok_or(Fail::End)?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
            .ok_or_else(|| Fail::Bad(String::from_utf8_lossy(token).into_owned()))
    }

    fn skip(&mut self, _ty: Scalar, n: usize) -> Result<(), Fail> {
        for _ in 0..n {
            self.token().ok_or(Fail::End)?;
        }
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    fn location(&self, _item: usize) -> usize {
        self.line
    }

    fn leftover(&mut self) -> Option<String> {
        self.token().map(|t| {
            format!(
                "unexpected data `{}` after the last element",
                String::from_utf8_lossy(t)
            )
        })
    }
}

/// Packed values of a binary body; `BIG` selects big-endian byte order.
pub(crate) struct BinaryValues<'a, const BIG: bool> {
    data: &'a [u8],
    pos: usize,
}

impl<'a, const BIG: bool> BinaryValues<'a, BIG> {
    /// Reads `data` from its start.
    pub fn new(data: &'a [u8]) -> Self {
        BinaryValues { data, pos: 0 }
    }

    /// The next `N` bytes.
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fail> {
        let bytes = self.data.get(self.pos..self.pos + N).ok_or(Fail::End)?;
        self.pos += N;
        bytes.try_into().map_err(|_| Fail::End)
    }
}

/// Decodes a number from its bytes in the body's byte order.
macro_rules! decode {
    ($self:ident, $t:ty, $n:literal) => {{
        let b = $self.take::<$n>()?;
        (if BIG {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }) as f64
    }};
}

impl<const BIG: bool> Values for BinaryValues<'_, BIG> {
    const BINARY: bool = true;

    fn value(&mut self, ty: Scalar) -> Result<f64, Fail> {
        Ok(match ty {
            Scalar::I8 => decode!(self, i8, 1),
            Scalar::U8 => decode!(self, u8, 1),
            Scalar::I16 => decode!(self, i16, 2),
            Scalar::U16 => decode!(self, u16, 2),
            Scalar::I32 => decode!(self, i32, 4),
            Scalar::U32 => decode!(self, u32, 4),
            Scalar::F32 => decode!(self, f32, 4),
            Scalar::F64 => decode!(self, f64, 8),
        })
    }

    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail> {
        let bytes = n.checked_mul(ty.size()).ok_or(Fail::End)?;
        if bytes > self.remaining() {
            return Err(Fail::End);
        }
        self.pos += bytes;
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    fn location(&self, item: usize) -> usize {
        item
    }

    fn leftover(&mut self) -> Option<String> {
        let n = self.remaining();
        (n > 0).then(|| format!("{n} bytes left after the last element"))
    }
}

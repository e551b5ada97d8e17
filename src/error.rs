//! The library's error type. Every fallible public function returns
//! `Result<T, subdyn::Error>`; the CLI prints it as one line.

use std::path::PathBuf;

/// Everything that can go wrong in subdyn, as a value.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A file was read but its contents are malformed.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line number (for binary files: the element number, 0 when unknown).
        line: usize,
        /// What was expected and what was found.
        message: String,
    },
    /// The mesh's connectivity cannot be subdivided (non-manifold edge, degenerate face, …).
    #[error("topology: {0}")]
    Topology(String),
    /// An argument or a value in the input is unusable (NaN coordinate,
    /// absurd parameter, arrays of different lengths, …); its
    /// [`InputError::kind`] says which.
    #[error("input: {0}")]
    Input(InputError),
    /// A step would allocate more than the memory budget ([`crate::memory`]).
    #[error("{what} needs about {}, over the memory budget of {} (--max-memory sets it)", crate::memory::human_bytes(*bytes), crate::memory::human_bytes(*budget))]
    Memory {
        /// What would be allocated.
        what: String,
        /// The estimate, bytes.
        bytes: u64,
        /// The budget, bytes.
        budget: u64,
    },
    /// An iterative method stopped before reaching its tolerance.
    #[error("not converged: {0}")]
    NotConverged(String),
}

impl Error {
    /// Shorthand for [`Error::Parse`].
    pub fn parse(path: impl Into<PathBuf>, line: usize, message: impl Into<String>) -> Self {
        Error::Parse {
            path: path.into(),
            line,
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Which kind of bad input an [`Error::Input`] reports, for a caller to
/// match on; the message says the rest in one line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum InputKind {
    /// Arrays that must have matching lengths do not (positions for a
    /// mesh, normals for points, values for a table's rows, …).
    SizeMismatch,
    /// A coordinate, parameter or result is NaN or infinite.
    NonFinite,
    /// An index names nothing (a vertex, face, cell or rope that does not
    /// exist), or a parameter is outside its documented range.
    OutOfRange,
    /// A file format or option that subdyn does not read or write.
    Unsupported,
    /// Anything else: a value the operation cannot use.
    Invalid,
}

/// The payload of [`Error::Input`]: its [`kind`](InputError::kind) and its
/// one-line message, which it dereferences to (`e.contains("…")`).
#[derive(Debug)]
pub struct InputError {
    kind: InputKind,
    message: String,
}

impl InputError {
    /// What kind of bad input this is.
    pub fn kind(&self) -> InputKind {
        self.kind
    }

    /// The one-line message.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::ops::Deref for InputError {
    type Target = str;
    fn deref(&self) -> &str {
        &self.message
    }
}

impl From<InputError> for String {
    fn from(e: InputError) -> String {
        e.message
    }
}

impl Error {
    /// [`Error::Input`] of `kind` (to re-word an input error, keeping its kind).
    pub fn with_kind(kind: InputKind, message: impl Into<String>) -> Self {
        Error::Input(InputError {
            kind,
            message: message.into(),
        })
    }

    /// [`Error::Input`] of kind [`InputKind::Invalid`].
    pub fn input(message: impl Into<String>) -> Self {
        Self::with_kind(InputKind::Invalid, message)
    }

    /// [`Error::Input`] of kind [`InputKind::SizeMismatch`].
    pub fn size_mismatch(message: impl Into<String>) -> Self {
        Self::with_kind(InputKind::SizeMismatch, message)
    }

    /// [`Error::Input`] of kind [`InputKind::NonFinite`].
    pub fn non_finite(message: impl Into<String>) -> Self {
        Self::with_kind(InputKind::NonFinite, message)
    }

    /// [`Error::Input`] of kind [`InputKind::OutOfRange`].
    pub fn out_of_range(message: impl Into<String>) -> Self {
        Self::with_kind(InputKind::OutOfRange, message)
    }

    /// [`Error::Input`] of kind [`InputKind::Unsupported`].
    pub fn unsupported(message: impl Into<String>) -> Self {
        Self::with_kind(InputKind::Unsupported, message)
    }

    /// The kind of an [`Error::Input`], `None` for the other variants.
    pub fn input_kind(&self) -> Option<InputKind> {
        match self {
            Error::Input(e) => Some(e.kind),
            _ => None,
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

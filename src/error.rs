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
    /// An argument or a value in the input is out of range (NaN coordinate, absurd parameter, …).
    #[error("input: {0}")]
    Input(String),
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

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

//! Errors of the data layer. Every variant that concerns a file names it.

use std::path::PathBuf;

/// Result type of `deepbrdf-data`.
pub type Result<T> = std::result::Result<T, DataError>;

/// What can go wrong reading, writing or transforming BRDF data.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// An operating-system error on a named path.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file whose content is not what its format requires (truncated, wrong header, NaN, ...).
    #[error("{path}: {problem}")]
    Format { path: PathBuf, problem: String },
    /// An argument or in-memory value that is out of range or inconsistent.
    #[error("{0}")]
    Invalid(String),
    /// A download of the MERL database failed (see [`crate::fetch`]).
    #[error(transparent)]
    Fetch(#[from] crate::fetch::FetchError),
}

impl DataError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }

    /// A format problem in the file at `path`.
    pub fn format(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self::Format { path: path.into(), problem: problem.into() }
    }
}

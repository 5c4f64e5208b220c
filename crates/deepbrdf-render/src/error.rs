//! Errors of `deepbrdf-render`. Every variant that concerns a file names it.

use std::path::PathBuf;

/// Result type of `deepbrdf-render`.
pub type Result<T> = std::result::Result<T, RenderError>;

/// What can go wrong building a scene, rendering or reading and writing images.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// An error of the data layer (a table, an atomic write).
    #[error(transparent)]
    Data(#[from] deepbrdf_data::DataError),
    /// A file whose content is not what its format requires, or that cannot be encoded.
    #[error("{path}: {problem}")]
    Format { path: PathBuf, problem: String },
    /// An argument or in-memory value that is out of range or inconsistent.
    #[error("{0}")]
    Invalid(String),
}

impl RenderError {
    /// A format problem in the file at `path`.
    pub fn format(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self::Format { path: path.into(), problem: problem.into() }
    }
}

//! Errors of `deepbrdf-eval`. Every variant that concerns a file names it.

use std::path::PathBuf;

/// Result type of `deepbrdf-eval`.
pub type Result<T> = std::result::Result<T, EvalError>;

/// What can go wrong fitting baselines, evaluating codecs, rendering or writing results.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// An error of the data layer (reading tables, the median reference, ...).
    #[error(transparent)]
    Data(#[from] deepbrdf_data::DataError),
    /// An error of the renderer (image-space measures, figures).
    #[error(transparent)]
    Render(#[from] deepbrdf_render::RenderError),
    /// An operating-system error on a named path.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file whose content is not what its format requires (truncated, wrong header, checksum).
    #[error("{path}: {problem}")]
    Format { path: PathBuf, problem: String },
    /// An argument or in-memory value that is out of range or inconsistent.
    #[error("{0}")]
    Invalid(String),
    /// An error raised by a method plugged into the harness (e.g. DeepBRDF's codec).
    #[error("{method}: {source}")]
    Method {
        method: String,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl EvalError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }

    /// A format problem in the file at `path`.
    pub fn format(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self::Format { path: path.into(), problem: problem.into() }
    }

    /// Wraps an error of a method implemented outside this crate (for [`crate::harness::Codec`]
    /// and [`crate::harness::Method`] implementations).
    pub fn method(
        method: impl Into<String>,
        source: impl Into<Box<dyn std::error::Error + Send + Sync>>,
    ) -> Self {
        Self::Method { method: method.into(), source: source.into() }
    }
}

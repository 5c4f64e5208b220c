//! Errors of `deepbrdf-model`. Every variant that concerns a file names it.

use std::path::PathBuf;

/// Result type of `deepbrdf-model`.
pub type Result<T> = std::result::Result<T, ModelError>;

/// What can go wrong building, training, saving or using a DeepBRDF network.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// An operating-system error on a named path.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file whose content is not what its format requires (truncated, foreign, bad checksum, ...).
    #[error("{path}: {problem}")]
    Format { path: PathBuf, problem: String },
    /// The parts of a model artifact or checkpoint do not belong together.
    #[error("{path}: {problem}")]
    Mismatch { path: PathBuf, problem: String },
    /// An argument or in-memory value that is out of range or inconsistent.
    #[error("{0}")]
    Invalid(String),
    /// Training produced a NaN or infinite loss; the last good checkpoint is kept.
    #[error(
        "training diverged: the loss is {loss} at epoch {epoch}, batch {batch}; \
         {kept} (resume from it with a smaller learning rate, e.g. --lr {suggested_lr:e})"
    )]
    NonFinite { loss: f32, epoch: usize, batch: usize, kept: String, suggested_lr: f64 },
    /// An error of the data layer.
    #[error(transparent)]
    Data(#[from] deepbrdf_data::DataError),
}

impl ModelError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }

    /// A format problem in the file at `path`.
    pub fn format(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self::Format { path: path.into(), problem: problem.into() }
    }

    /// Parts at `path` that do not belong together.
    pub fn mismatch(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self::Mismatch { path: path.into(), problem: problem.into() }
    }
}

//! The library crates' errors as Python exceptions: a file that cannot be opened is the
//! `OSError` subclass of its errno (`FileNotFoundError`, `PermissionError`, ...) with `filename`
//! set, a file whose content is wrong a [`FileFormatError`] (an `OSError`); a bad
//! argument or array is a `ValueError`; anything else a `RuntimeError`. The message is the
//! library's, which names the file.
use deepbrdf_data::DataError;
use deepbrdf_eval::EvalError;
use deepbrdf_model::ModelError;
use deepbrdf_render::RenderError;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::Path;

pyo3::create_exception!(
    deepbrdf,
    FileFormatError,
    PyOSError,
    "A file that exists but is not what its format requires (truncated, wrong header, a \
     value out of range, a model of another kind); the message names it."
);

/// What an error is, for Python.
enum Kind<'a> {
    /// An operating-system error on a file.
    Io(&'a Path, &'a std::io::Error),
    /// A file whose content is wrong.
    File,
    /// A bad argument or value.
    Invalid,
    /// Anything else.
    Other,
}

fn data_kind(e: &DataError) -> Kind<'_> {
    match e {
        DataError::Io { path, source } => Kind::Io(path, source),
        DataError::Format { .. } => Kind::File,
        DataError::Invalid(_) => Kind::Invalid,
        DataError::Fetch(_) => Kind::Other,
    }
}

fn model_kind(e: &ModelError) -> Kind<'_> {
    match e {
        ModelError::Io { path, source } => Kind::Io(path, source),
        ModelError::Format { .. } | ModelError::Mismatch { .. } => Kind::File,
        ModelError::Invalid(_) => Kind::Invalid,
        ModelError::Data(d) => data_kind(d),
        ModelError::NonFinite { .. } => Kind::Other,
    }
}

fn render_kind(e: &RenderError) -> Kind<'_> {
    match e {
        RenderError::Data(d) => data_kind(d),
        RenderError::Format { .. } => Kind::File,
        RenderError::Invalid(_) => Kind::Invalid,
    }
}

fn eval_kind(e: &EvalError) -> Kind<'_> {
    match e {
        EvalError::Data(d) => data_kind(d),
        EvalError::Render(r) => render_kind(r),
        EvalError::Io { path, source } => Kind::Io(path, source),
        EvalError::Format { .. } => Kind::File,
        EvalError::Invalid(_) => Kind::Invalid,
        EvalError::Method { source, .. } => {
            if let Some(m) = source.downcast_ref::<ModelError>() {
                model_kind(m)
            } else if let Some(e) = source.downcast_ref::<EvalError>() {
                eval_kind(e)
            } else if let Some(d) = source.downcast_ref::<DataError>() {
                data_kind(d)
            } else if let Some(r) = source.downcast_ref::<RenderError>() {
                render_kind(r)
            } else {
                Kind::Other
            }
        }
    }
}

/// The Python exception of an error of `kind` with the library's `message`.
fn exception(kind: Kind<'_>, message: String) -> PyErr {
    match kind {
        Kind::Io(path, source) => match source.raw_os_error() {
            // OSError(errno, strerror, filename) is the errno's subclass (FileNotFoundError, ...).
            Some(errno) => {
                let text = std::io::Error::from_raw_os_error(errno).to_string();
                let strerror = match text.rfind(" (os error") {
                    Some(at) => text[..at].to_string(),
                    None => text,
                };
                PyOSError::new_err((errno, strerror, path.display().to_string()))
            }
            None => file_format_error(message),
        },
        Kind::File => file_format_error(message),
        Kind::Invalid => PyValueError::new_err(message),
        Kind::Other => PyRuntimeError::new_err(message),
    }
}

/// A [`FileFormatError`]: the library's message names the file (`filename` is left unset, as
/// Python would print it as an errno message).
fn file_format_error(message: String) -> PyErr {
    FileFormatError::new_err(message)
}

/// An error of the library crates, for `map_err`.
pub trait ToPyErr: std::fmt::Display {
    fn to_py(&self) -> PyErr;
}

impl ToPyErr for DataError {
    fn to_py(&self) -> PyErr {
        exception(data_kind(self), self.to_string())
    }
}

impl ToPyErr for ModelError {
    fn to_py(&self) -> PyErr {
        exception(model_kind(self), self.to_string())
    }
}

impl ToPyErr for RenderError {
    fn to_py(&self) -> PyErr {
        exception(render_kind(self), self.to_string())
    }
}

impl ToPyErr for EvalError {
    fn to_py(&self) -> PyErr {
        exception(eval_kind(self), self.to_string())
    }
}

/// `map_err(py_err)`: the Python exception of a library error.
pub fn py_err<E: ToPyErr>(e: E) -> PyErr {
    e.to_py()
}

/// A `ValueError` with `message` (bad arrays and arguments).
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

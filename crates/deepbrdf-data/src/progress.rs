//! Progress reporting for long work, without a terminal dependency: library code calls a
//! [`Progress`]; only the `experiments` binary renders it (with indicatif), as uv does.

/// Receives progress of a long operation. Implementations must be cheap and thread-safe.
pub trait Progress: Sync {
    /// A new phase of `len` steps named `message` begins.
    fn start(&self, len: u64, message: &str);
    /// `n` more steps are done.
    fn advance(&self, n: u64);
    /// A short status (e.g. the current loss) for the current phase.
    fn status(&self, _status: &str) {}
    /// The current phase is finished.
    fn finish(&self);
}

/// A [`Progress`] that shows nothing: for tests and quiet runs.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {
    fn start(&self, _len: u64, _message: &str) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
}

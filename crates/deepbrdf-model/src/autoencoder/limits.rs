//! The size guard every network configuration checks against.

/// Largest layer width, latent dimension or basis size accepted (a guard against typos that
/// would allocate terabytes).
pub(crate) const MAX_WIDTH: usize = 4096;

//! `deepbrdf-data`: measured BRDF data for DeepBRDF (Hu et al., CGF 2020, §3.1).
pub mod error;
pub mod fetch;
pub mod merl;
pub mod progress;

pub use error::{DataError, Result};
pub use merl::MerlTable;
pub use progress::{Progress, Silent};

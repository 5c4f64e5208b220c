//! `deepbrdf-eval`: evaluation of measured-BRDF representations (Hu et al., CGF 2020, §4):
//! the PCA and IPCA baselines, the evaluation harness shared with DeepBRDF, and figures.
pub mod attributes;
pub mod baseline;
pub mod editing;
pub mod error;
pub mod figures;
pub mod harness;
pub mod ipca;
pub mod metrics;
pub mod pca;

pub use error::{EvalError, Result};

//! The attribute-to-latent regressor of §5.1 (Hu et al. 2020, eq. (7), Fig. 11): a small MLP,
//! 7 -> 100 (leaky ReLU) -> k, from a material's 7 editable attributes (diffuse albedo RGB,
//! specular albedo RGB, roughness; `deepbrdf_eval::attributes`) to its k latent values under one
//! DeepBRDF model (or its k IPCA coefficients, for the paper's Fig. 14 comparison), trained with
//! the relative loss `||Y^ - Y|| / ||Y||` through the shared loop ([`crate::train::run`]).
//!
//! One concept per file: [`scaling`] (the recorded normalisation of inputs and targets),
//! [`network`] (the MLP), [`training`] (its [`crate::train::TrainStep`] and settings),
//! [`artifact`] (the saved regressor that names the representation it belongs to).

pub mod artifact;
pub mod network;
pub mod scaling;
pub mod training;

pub use artifact::{Regressor, RegressorProvenance, Target, TargetKind, REGRESSOR_KIND};
pub use network::{NetworkShape, RegressorNet, ATTRIBUTES};
pub use scaling::Scaling;
pub use training::{train_regressor, RegressorConfig, RegressorData};

#[cfg(test)]
mod tests;

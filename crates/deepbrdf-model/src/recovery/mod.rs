//! Single-image BRDF recovery (Hu et al. 2020, §5.2, Fig. 15): a CNN maps a photo of one object
//! to DeepBRDF's latent vector, and the frozen decoder turns that into a full MERL table.
//!
//! - [`network`]: the CNN (three convolutions, two max-poolings, two fully connected layers)
//!   and its configuration; [`preset`]: the `paper` and `small` settings.
//! - [`step`]: its training step through the shared loop (`crate::train::run`), L1 loss.
//! - [`artifact`]: the saved network, checksummed, naming the DeepBRDF model whose latent it
//!   predicts (or the 7 analytic attributes, for the baseline of the same CNN with 7 outputs).

pub mod artifact;
pub mod network;
pub mod preset;
pub mod step;

pub use artifact::{RecoveryArtifact, RecoveryProvenance, RecoveryTarget};
pub use network::{RecoveryConfig, RecoveryNet};
pub use preset::RecoveryPreset;
pub use step::{train_recovery, RecoveryData, RecoveryTrained};

#[cfg(test)]
mod tests;

//! The settings every network's training shares: optimizer, learning-rate schedule, epochs,
//! batch size, seed and checkpoint interval (§3.2 gives the autoencoder's: Adam, lr 2e-5,
//! batches of 32, 1000 epochs).

use burn::optim::AdamConfig;
use burn::prelude::*;

use crate::error::ModelError;

/// How a training loop runs, whatever the network ([`super::run`]).
#[derive(Config, Debug)]
pub struct LoopConfig {
    /// Adam's settings (§3.2: Adam [KB14]; see [`adam`]).
    pub optimizer: AdamConfig,
    /// Initial learning rate.
    #[config(default = 1e-3)]
    pub learning_rate: f64,
    /// The learning rate falls along a half cosine to `learning_rate * final_lr_factor` at the
    /// last step; 1.0 keeps it constant ([`super::schedule`]).
    #[config(default = 1.0)]
    pub final_lr_factor: f64,
    /// The learning rate rises linearly from `learning_rate / warm-up steps` over the first
    /// this many epochs (0: no warm-up; [`super::schedule`]).
    #[config(default = 0.0)]
    pub warmup_epochs: f64,
    /// Passes over the training examples.
    #[config(default = 100)]
    pub epochs: usize,
    /// Examples per mini-batch (the last one of an epoch may be shorter).
    #[config(default = 32)]
    pub batch_size: usize,
    /// Seed of the epoch orders (and, by convention, of the network's initialisation).
    #[config(default = 0)]
    pub seed: u64,
    /// A checkpoint is written at the end of an epoch once this many seconds have passed since
    /// the last one, and after a batch within an epoch likewise; always after the last epoch.
    #[config(default = 60.0)]
    pub checkpoint_seconds: f64,
}

/// Adam as PyTorch (the paper's framework) defines it: epsilon 1e-8. Burn's default, 1e-5, is
/// larger than most of the autoencoder's gradients (eq. (4) divides by the ~3.3 million valid
/// values of each BRDF), which turns Adam into plain, tiny gradient steps: the loss then stays
/// at the variance of the data.
pub fn adam() -> AdamConfig {
    AdamConfig::new().with_epsilon(1e-8)
}

impl LoopConfig {
    /// Checks the settings once.
    pub fn validate(&self) -> crate::error::Result<()> {
        let lr_ok = self.learning_rate.is_finite() && self.learning_rate > 0.0;
        if !lr_ok || !(self.final_lr_factor > 0.0 && self.final_lr_factor <= 1.0) {
            return Err(ModelError::Invalid(format!(
                "learning rate {} with final factor {} (need lr > 0 and 0 < factor <= 1)",
                self.learning_rate, self.final_lr_factor
            )));
        }
        if !(self.warmup_epochs >= 0.0 && self.warmup_epochs <= self.epochs as f64) {
            return Err(ModelError::Invalid(format!(
                "a warm-up of {} epochs (need 0 to the {} epochs of the run)",
                self.warmup_epochs, self.epochs
            )));
        }
        if self.epochs == 0 || self.batch_size == 0 || self.batch_size > 4096 {
            return Err(ModelError::Invalid(format!(
                "{} epochs of batches of {} (both must be positive, batches at most 4096)",
                self.epochs, self.batch_size
            )));
        }
        if !(self.checkpoint_seconds >= 0.0) {
            return Err(ModelError::Invalid("checkpoint interval must be >= 0 seconds".into()));
        }
        Ok(())
    }
}

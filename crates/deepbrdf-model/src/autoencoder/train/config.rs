//! The autoencoder's training configuration (§3.2): the network, the loop's settings (Adam,
//! schedule, epochs, batches, seed, checkpoints) side by side in one flat JSON object as
//! earlier versions wrote it, shards per batch and slice dropout; the two presets; reading it
//! from a file with errors that name the file.

use std::path::Path;

use burn::optim::AdamConfig;
use burn::prelude::*;
use deepbrdf_data::augment::SliceSelection;

use super::batch::SliceDropout;
use crate::artifact::files::read_limited;
use crate::autoencoder::{Autoencoder, AutoencoderConfig};
use crate::error::ModelError;
use crate::loss::LossNorm;
use crate::train::checkpoint::{self, CHECKPOINT_FILE};
use crate::train::config::{adam, LoopConfig};

/// Everything that determines a training run of the autoencoder. Saved as JSON beside the
/// checkpoint and in the model's provenance.
///
/// The loop's six settings (optimizer to checkpoint interval) are [`LoopConfig`]'s, declared
/// here again rather than nested, and [`TrainConfig::loop_config`] hands them to the loop: the
/// file is one flat JSON object (as `models/default/train_config.json` and every checkpoint
/// hold it), Burn's `Config` derive cannot flatten a nested config into its parent's object,
/// and the defaults differ (§3.2's here, the shared loop's there). Nesting would change
/// the file the shipped model was trained from, so the flat layout stays.
#[derive(Config, Debug)]
pub struct TrainConfig {
    /// The network.
    pub model: AutoencoderConfig,
    /// Adam's settings (§3.2: Adam [KB14]).
    pub optimizer: AdamConfig,
    /// Initial learning rate (§3.2: 2e-5).
    #[config(default = 2e-5)]
    pub learning_rate: f64,
    /// The learning rate falls along a half cosine to `learning_rate * final_lr_factor` at the
    /// last step; 1.0 keeps it constant (the paper's setting).
    #[config(default = 1.0)]
    pub final_lr_factor: f64,
    /// Epochs over which the learning rate rises linearly to its schedule's (none in the
    /// paper; none when absent, as in a configuration written before the field existed).
    #[config(default = "None")]
    pub warmup_epochs: Option<f64>,
    /// Passes over the training set (§3.2: 1000).
    #[config(default = 1000)]
    pub epochs: usize,
    /// BRDFs per mini-batch (§3.2: 32).
    #[config(default = 32)]
    pub batch_size: usize,
    /// Seed of the weight initialisation, the shuffling and the slice dropout.
    #[config(default = 0)]
    pub seed: u64,
    /// A checkpoint is written at the end of every epoch and, within an epoch, after a batch
    /// once this many seconds have passed since the last one.
    #[config(default = 60.0)]
    pub checkpoint_seconds: f64,
    /// Each batch of a convolutional network is split into this many shards computed in
    /// parallel on CPU backends (1 on a GPU). Results depend on it (summation order), so it is
    /// part of the configuration.
    #[config(default = 1)]
    pub threads: usize,
    /// Slice-dropout augmentation (§3.2, Fig. 2); none in the paper's training.
    #[config(default = "None")]
    pub slice_dropout: Option<SliceDropoutConfig>,
    /// The norm of eq. (4); none is L2, the paper's (a configuration written before the field
    /// existed has none). L1 is for Fig. 4's comparison.
    #[config(default = "None")]
    pub loss_norm: Option<LossNorm>,
}

/// Slice-dropout augmentation: some training inputs lose phi_d slices, each missing slice
/// filled from its nearest kept one (§3.2, `deepbrdf_data::augment`), while the target stays
/// the full BRDF, so the network learns the Fig. 2 task of completing sparse inputs.
#[derive(Config, Debug, PartialEq)]
pub struct SliceDropoutConfig {
    /// Probability that a training input is shown with missing slices.
    #[config(default = 0.5)]
    pub probability: f64,
    /// The selections drawn from, uniformly (`every:N` or `random:K`, as
    /// `deepbrdf_data::augment::SliceSelection` parses them); Fig. 2 uses 1/3 and 1/9.
    #[config(default = "vec![\"every:3\".to_string(), \"every:9\".to_string()]")]
    pub selections: Vec<String>,
}

impl SliceDropoutConfig {
    /// The parsed selections, or an error naming the bad one.
    pub fn parsed(&self) -> crate::error::Result<Vec<SliceSelection>> {
        if !(0.0..=1.0).contains(&self.probability) {
            return Err(ModelError::Invalid(format!(
                "slice-dropout probability {} is not in [0, 1]",
                self.probability
            )));
        }
        if self.selections.is_empty() {
            return Err(ModelError::Invalid("slice dropout needs at least one selection".into()));
        }
        self.selections.iter().map(|s| Ok(s.parse::<SliceSelection>()?)).collect()
    }
}

/// Epochs of the `slice` preset (over the augmented set: 10x the BRDFs with the preset's
/// augmentation).
pub const SLICE_EPOCHS: usize = 60;

/// Largest configuration file read (they are a few hundred bytes).
const MAX_CONFIG_BYTES: u64 = 1 << 20;

impl TrainConfig {
    /// §3.2's settings: Table 1, Adam with lr 2e-5, batches of 32, 1000 epochs.
    pub fn paper(k: usize) -> Self {
        Self::new(AutoencoderConfig::paper(k), adam())
    }

    /// The `slice` preset, the shipped default model's: the network of
    /// [`AutoencoderConfig::slice`] (one basis for all phi_d slices, a decoder MLP shared by
    /// them, channel permutations and mixtures as extra training BRDFs), Adam 1e-3 with cosine
    /// decay to 5e-5, batches of 32, slice dropout (half the inputs shown with 1/3 or 1/9 of
    /// the slices, §3.2). Bounded to a few minutes on two cores for 100 BRDFs
    /// (docs/model.md has the measured times).
    pub fn slice(k: usize) -> Self {
        Self::new(AutoencoderConfig::slice(k), adam())
            .with_learning_rate(1e-3)
            .with_final_lr_factor(0.05)
            .with_epochs(SLICE_EPOCHS)
            .with_batch_size(32)
            .with_threads(1)
            .with_slice_dropout(Some(SliceDropoutConfig::new()))
    }

    /// The configuration in the JSON file `path`, checked; an error names the file and the
    /// problem (unreadable, not JSON, a missing or unknown field, a value out of range).
    pub fn from_file(path: &Path) -> crate::error::Result<Self> {
        Self::parse(path, &read_limited(path, MAX_CONFIG_BYTES)?)
    }

    /// The configuration in `bytes` (the content of `path`, named in errors), checked.
    pub fn parse(path: &Path, bytes: &[u8]) -> crate::error::Result<Self> {
        let config: Self = serde_json::from_slice(bytes)
            .map_err(|e| ModelError::format(path, format!("not a training configuration: {e}")))?;
        config.validate().map_err(|e| ModelError::format(path, e.to_string()))?;
        Ok(config)
    }

    /// The norm of eq. (4) this run trains with.
    pub fn norm(&self) -> LossNorm {
        self.loss_norm.unwrap_or_default()
    }

    /// The schedule in a few words: initialisation, offset and scale, optimiser's rate,
    /// warm-up and decay, batch size, slice dropout.
    pub fn schedule_summary(&self) -> String {
        let mut parts = Vec::new();
        if let crate::autoencoder::Architecture::Convolutional(c) = &self.model.architecture {
            parts.push(if c.he_init { "He init" } else { "PyTorch init" }.to_string());
            if c.standardise == Some(true) {
                parts.push("standardised per value".into());
            } else if c.mean_offset {
                parts.push("mean offset".into());
            }
        }
        let mut rate = format!("Adam {:.0e}", self.learning_rate);
        if let Some(w) = self.warmup_epochs.filter(|&w| w > 0.0) {
            rate.push_str(&format!(", warm-up {w} epochs"));
        }
        if self.final_lr_factor < 1.0 {
            rate.push_str(&format!(
                ", cosine to x{} over {} epochs",
                self.final_lr_factor, self.epochs
            ));
        }
        parts.push(rate);
        parts.push(format!("batch {}", self.batch_size));
        if self.slice_dropout.is_some() {
            parts.push("slice dropout".into());
        }
        parts.join(", ")
    }

    /// The loop's settings of this configuration.
    pub fn loop_config(&self) -> LoopConfig {
        LoopConfig::new(self.optimizer.clone())
            .with_learning_rate(self.learning_rate)
            .with_final_lr_factor(self.final_lr_factor)
            .with_warmup_epochs(self.warmup_epochs.unwrap_or(0.0))
            .with_epochs(self.epochs)
            .with_batch_size(self.batch_size)
            .with_seed(self.seed)
            .with_checkpoint_seconds(self.checkpoint_seconds)
    }

    /// Checks the settings once.
    pub fn validate(&self) -> crate::error::Result<()> {
        self.model.validate()?;
        self.loop_config().validate()?;
        if self.threads == 0 || self.threads > 64 {
            return Err(ModelError::Invalid(format!("{} threads (1 to 64)", self.threads)));
        }
        if let Some(dropout) = &self.slice_dropout {
            dropout.parsed()?;
        }
        Ok(())
    }

    /// Slice dropout's probability and parsed selections with the run's seed, if it is on.
    pub(crate) fn dropout(&self) -> crate::error::Result<Option<SliceDropout>> {
        match &self.slice_dropout {
            Some(d) => Ok(Some(SliceDropout {
                probability: d.probability,
                selections: d.parsed()?,
                seed: self.seed,
            })),
            None => Ok(None),
        }
    }

    /// The network of a new run, its weights drawn from the run's seed. Seeded even when
    /// resuming: an unseeded draw from the shared generator could fall between the seeding
    /// and the draws of another run's initialisation.
    pub(crate) fn init_network(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.model.init_seeded(self.seed, device)
    }

    /// The learning rate of step `step` of `total` ([`LoopConfig::learning_rate_at`]).
    pub fn learning_rate_at(&self, step: usize, total: usize) -> f64 {
        self.loop_config().learning_rate_at(step, total)
    }
}

/// The configuration of the run saved in `out_dir` (from its checkpoint), to resume it.
pub fn saved_config(out_dir: &Path) -> crate::error::Result<TrainConfig> {
    let path = out_dir.join(CHECKPOINT_FILE);
    let config = checkpoint::saved_run_config(&path)?;
    serde_json::from_value(config)
        .map_err(|e| ModelError::format(&path, format!("bad configuration: {e}")))
}

#[cfg(test)]
#[path = "config_fuzz.rs"]
mod fuzz;

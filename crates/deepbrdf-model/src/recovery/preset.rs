//! The recovery CNN's presets: `paper` (§5.2: 256x256 inputs, Adam with learning rate 1e-3,
//! batches of 64, 300 epochs; for a GPU) and `small` (64x64 inputs, narrower layers, fewer
//! epochs: trains in minutes on two cores; its earlier name `cpu` still parses).

use std::str::FromStr;

use crate::train::{adam, LoopConfig};

use super::network::RecoveryConfig;

/// A network-and-training preset of the recovery CNN.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecoveryPreset {
    /// 64x64 inputs; conv 5x5/2 (24), pool, conv 3x3 (48), pool, conv 3x3 (48), FC 128;
    /// Adam 1e-3 falling to 1e-4, batches of 32, 40 epochs.
    Small,
    /// The paper: 256x256 inputs; conv 5x5/2 (32), pool, conv 3x3 (64), pool, conv 3x3/2 (64),
    /// FC 256; Adam 1e-3, batches of 64, 300 epochs.
    Paper,
}

impl RecoveryPreset {
    /// The network for `outputs` outputs.
    pub fn network(self, outputs: usize) -> RecoveryConfig {
        match self {
            Self::Small => {
                RecoveryConfig::new(64, [24, 48, 48], [5, 3, 3], [2, 1, 1], 128, outputs)
            }
            Self::Paper => {
                RecoveryConfig::new(256, [32, 64, 64], [5, 3, 3], [2, 1, 2], 256, outputs)
            }
        }
    }

    /// The training loop's settings.
    pub fn loop_config(self) -> LoopConfig {
        match self {
            Self::Small => LoopConfig::new(adam())
                .with_learning_rate(1e-3)
                .with_final_lr_factor(0.1)
                .with_epochs(40)
                .with_batch_size(32)
                .with_checkpoint_seconds(30.0),
            Self::Paper => LoopConfig::new(adam())
                .with_learning_rate(1e-3)
                .with_epochs(300)
                .with_batch_size(64)
                .with_checkpoint_seconds(120.0),
        }
    }
}

deepbrdf_data::named_enum!(RecoveryPreset { Small => "small", Paper => "paper" });

impl FromStr for RecoveryPreset {
    type Err = String;

    /// A preset's name, or `cpu`, the earlier name of `small`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("cpu") {
            return Ok(Self::Small);
        }
        Self::from_name(s)
            .ok_or_else(|| format!("unknown recovery preset '{s}': expected small or paper"))
    }
}

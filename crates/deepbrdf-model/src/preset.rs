//! Named settings: `paper` (Table 1 and §3.2's training) and `cpu` (sized for a 2-core CPU).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::train::TrainConfig;

/// A network-and-training preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// Sized for a 2-core CPU: see [`crate::AutoencoderConfig::cpu`] and [`TrainConfig::cpu`].
    Cpu,
    /// The paper: Table 1, Adam lr 2e-5, batches of 32, 1000 epochs (for GPUs).
    Paper,
}

impl Preset {
    /// Both presets.
    pub const ALL: [Preset; 2] = [Preset::Cpu, Preset::Paper];

    /// The preset's training configuration for latent dimension `k`.
    pub fn train_config(self, k: usize) -> TrainConfig {
        match self {
            Preset::Cpu => TrainConfig::cpu(k),
            Preset::Paper => TrainConfig::paper(k),
        }
    }

    /// The preset's name.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Cpu => "cpu",
            Preset::Paper => "paper",
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| format!("unknown preset '{s}': expected cpu or paper"))
    }
}

//! Named settings: `paper` (Table 1 and §3.2's training) and `slice` (the network shared
//! across phi_d slices that ships as the default model).

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::autoencoder::train::TrainConfig;

/// A network-and-training preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// The paper: Table 1, Adam lr 2e-5, batches of 32, 1000 epochs (for GPUs).
    Paper,
    /// One basis and one decoder MLP shared by all phi_d slices, small enough to ship: see
    /// [`crate::AutoencoderConfig::slice`] and [`TrainConfig::slice`].
    Slice,
}

deepbrdf_data::named_enum!(Preset { Paper => "paper", Slice => "slice" });

impl Preset {
    /// The preset's training configuration for latent dimension `k`.
    pub fn train_config(self, k: usize) -> TrainConfig {
        match self {
            Preset::Paper => TrainConfig::paper(k),
            Preset::Slice => TrainConfig::slice(k),
        }
    }
}

impl FromStr for Preset {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| match s.trim().eq_ignore_ascii_case("cpu") {
            true => format!("the preset '{s}' was retired: use slice (the shipped model's)"),
            false => format!("unknown preset '{s}': expected paper or slice"),
        })
    }
}

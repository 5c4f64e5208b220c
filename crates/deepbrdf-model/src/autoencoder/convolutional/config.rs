//! The layers of Table 1's convolutional network and the checks of their sizes.

use burn::config::Config;
use serde::{Deserialize, Serialize};

use crate::autoencoder::limits::MAX_WIDTH;
use crate::error::ModelError;

/// The layers of Table 1's convolutional network.
#[derive(Config, Debug, PartialEq)]
pub struct ConvolutionalConfig {
    /// Width C of a per-pixel 1x1 projection 540 -> C applied first (and C -> 540 applied
    /// last); `None` in Table 1, where the strided convolutions see all 540 channels.
    #[config(default = "None")]
    pub projection: Option<usize>,
    /// Output channels of the three 3x3 stride-2 convolutions (Table 1: 256, 128, 64).
    #[config(default = "[256, 128, 64]")]
    pub encoder_channels: [usize; 3],
    /// Number of residual blocks at the bottleneck (Table 1: 3).
    #[config(default = 3)]
    pub residual_blocks: usize,
    /// Output channels of the first two deconvolutions (Table 1: 128 at 24 x 24, 256 at 48 x 48).
    #[config(default = "[128, 256]")]
    pub decoder_channels: [usize; 2],
    /// Predict deviations from a fixed per-value offset (the training mean in mapped space,
    /// set with [`crate::Autoencoder::with_offset`]); the input is centred on it too. Not in Table 1.
    #[config(default = false)]
    pub mean_offset: bool,
    /// Standardise per value: with the mean offset, the encoder sees each centred value divided
    /// by its spread over the training set, and the decoder's output is multiplied by it (a
    /// fixed per-value scale, set with [`crate::Autoencoder::with_scale`]), so every value is
    /// learnt on one scale. Not in Table 1; none when absent (as in a configuration written
    /// before the field existed).
    #[config(default = "None")]
    pub standardise: Option<bool>,
    /// He initialisation (normal, gain sqrt(2) for the leaky ReLUs, the residual blocks'
    /// second convolutions at zero so they start as identities) instead of PyTorch's default
    /// (uniform, gain 1/sqrt(3)), under which activations shrink layer after layer and the
    /// latent vector starts near zero. Not a Table 1 setting; training converges much faster.
    #[config(default = false)]
    pub he_init: bool,
    /// How the convolutions are computed: the same parameters and values either way (within
    /// f32 rounding), so a model saved with one loads and runs with the other.
    #[config(default = "ConvAlgorithm::Gemm")]
    pub conv: ConvAlgorithm,
}

/// How Table 1's convolutions and transposed convolutions are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ConvAlgorithm {
    /// Burn's `Conv2d` and `ConvTranspose2d` modules as they are (on its GPU backends without
    /// kernel autotuning: a direct convolution kernel for every pass).
    Direct,
    /// As matrix products ([`super::gemm`]): shifted slices stacked into columns, one batched
    /// product per layer; the transposed convolutions by their sub-pixel phases.
    Gemm,
}

deepbrdf_data::named_enum!(ConvAlgorithm { Direct => "direct", Gemm => "gemm" });

impl std::str::FromStr for ConvAlgorithm {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s)
            .ok_or_else(|| format!("unknown convolution algorithm '{s}': expected gemm or direct"))
    }
}

impl ConvolutionalConfig {
    /// Checks the layer widths and the number of residual blocks.
    pub fn validate(&self) -> crate::error::Result<()> {
        let widths = self
            .encoder_channels
            .iter()
            .chain(self.decoder_channels.iter())
            .chain(self.projection.iter());
        if let Some(w) = widths.into_iter().find(|&&w| w == 0 || w > MAX_WIDTH) {
            return Err(ModelError::Invalid(format!(
                "a layer width of {w} is out of range (1 to {MAX_WIDTH})"
            )));
        }
        if self.standardise == Some(true) && !self.mean_offset {
            return Err(ModelError::Invalid(
                "standardising per value needs the mean offset (mean_offset: true)".into(),
            ));
        }
        if self.residual_blocks > 64 {
            return Err(ModelError::Invalid(format!(
                "{} residual blocks is out of range (0 to 64)",
                self.residual_blocks
            )));
        }
        Ok(())
    }
}

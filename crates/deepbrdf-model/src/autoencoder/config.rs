//! The autoencoder's configuration: the latent dimension k, the leaky ReLU slope and one
//! [`Architecture`] (Table 1's convolutional network or the `slice` preset's network), with
//! the two presets and the checks that keep [`AutoencoderConfig::init`] from building a
//! degenerate network.

use burn::config::Config;
use burn::nn::Initializer;
use burn::prelude::*;
use serde::{Deserialize, Serialize};

use super::convolutional::Convolutional;
use super::retired;
use super::slice_network::SliceNetwork;
use super::Autoencoder;
use crate::augmentation::AugmentationConfig;
use crate::error::ModelError;

/// Architecture of the autoencoder: k ([`latent`](Self::latent)) is the FC-10 of Table 1.
///
/// Serialised as `{"latent": k, "negative_slope": s, "architecture": {...}}`; a configuration
/// of a retired network (see [`super::retired`]) is refused with what to do.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "serde_json::Value")]
pub struct AutoencoderConfig {
    /// k, the dimension of the latent vector (Table 1's FC-10; §3.2 studies 5 to 40).
    pub latent: usize,
    /// Negative slope of the leaky ReLUs (PyTorch's default, as the paper does not say).
    pub negative_slope: f64,
    /// Which network maps a BRDF to its k latent values and back.
    pub architecture: Architecture,
}

impl Config for AutoencoderConfig {}

impl std::fmt::Display for AutoencoderConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&burn::config::config_to_json(self))
    }
}

/// The networks an autoencoder can be. New ones (say, a network for a new input layout) are new
/// variants here and in [`Autoencoder`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Architecture {
    /// Table 1's convolutional encoder and decoder (and narrower variants of it).
    Convolutional(ConvolutionalConfig),
    /// The `slice` preset: one basis for the (theta_h, theta_d) images of every phi_d slice and
    /// colour, a decoder MLP shared by the slices ([`super::slice_network`]).
    Slice(SliceConfig),
}

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
    /// set with [`Autoencoder::with_offset`]); the input is centred on it too. Not in Table 1.
    #[config(default = false)]
    pub mean_offset: bool,
    /// He initialisation (normal, gain sqrt(2) for the leaky ReLUs, the residual blocks'
    /// second convolutions at zero so they start as identities) instead of PyTorch's default
    /// (uniform, gain 1/sqrt(3)), under which activations shrink layer after layer and the
    /// latent vector starts near zero. Not a Table 1 setting; training converges much faster.
    #[config(default = false)]
    pub he_init: bool,
}

/// The `slice` preset's network ([`super::slice_network`]; not in the paper).
#[derive(Config, Debug, PartialEq)]
pub struct SliceConfig {
    /// M, the directions of the basis shared by the 540 images of a BRDF.
    #[config(default = 64)]
    pub directions: usize,
    /// K >= k, the principal components of the coefficient vectors the encoder MLP sees (the
    /// first k are the linear path).
    #[config(default = 40)]
    pub components: usize,
    /// Width of the encoder MLP and of the decoder MLP shared by the slices (none: linear,
    /// PCA within the slice basis' span).
    #[config(default = "Some(128)")]
    pub hidden: Option<usize>,
    /// H, the Fourier harmonics of phi_d the decoder MLP sees.
    #[config(default = 4)]
    pub harmonics: usize,
    /// Extra training BRDFs (channel permutations, mixtures), used by the fits of the mean
    /// and components and by training.
    #[config(default = "AugmentationConfig::new()")]
    pub augmentation: AugmentationConfig,
}

/// M of the `slice` preset.
pub const SLICE_DIRECTIONS: usize = 64;

/// Largest layer width, latent dimension or basis size accepted (a guard against typos that
/// would allocate terabytes).
const MAX_WIDTH: usize = 4096;

impl AutoencoderConfig {
    /// A network of `architecture` with latent dimension `k` and PyTorch's leaky ReLU slope.
    pub fn new(k: usize, architecture: Architecture) -> Self {
        Self { latent: k, negative_slope: 0.01, architecture }
    }

    /// Table 1 exactly, with latent dimension `k`.
    pub fn paper(k: usize) -> Self {
        Self::convolutional(k, ConvolutionalConfig::new())
    }

    /// A convolutional network of latent dimension `k`.
    pub fn convolutional(k: usize, layers: ConvolutionalConfig) -> Self {
        Self::new(k, Architecture::Convolutional(layers))
    }

    /// The `slice` preset ([`super::slice_network`]): a basis of [`SLICE_DIRECTIONS`]
    /// directions shared by all phi_d slices and colours, max(40, k) principal components of
    /// the coefficients, MLPs of width 128, the decoder's shared by the slices; trained with
    /// channel permutations and pairwise mixtures of the training BRDFs
    /// ([`AugmentationConfig`]). The whole network is ~2 M values: it ships.
    pub fn slice(k: usize) -> Self {
        Self::new(
            k,
            Architecture::Slice(
                SliceConfig::new()
                    .with_directions(SLICE_DIRECTIONS)
                    .with_components(k.max(40))
                    .with_augmentation(AugmentationConfig::preset()),
            ),
        )
    }

    /// The slice network's settings, if it is one.
    pub fn slice_config(&self) -> Option<&SliceConfig> {
        match &self.architecture {
            Architecture::Slice(s) => Some(s),
            _ => None,
        }
    }

    /// Whether the network predicts deviations from a fixed offset (the training mean): by
    /// [`ConvolutionalConfig::mean_offset`] for a convolutional one, never for a slice one.
    pub fn mean_offset(&self) -> bool {
        match &self.architecture {
            Architecture::Convolutional(c) => c.mean_offset,
            Architecture::Slice(_) => false,
        }
    }

    /// The initializer of hidden layers (followed by a leaky ReLU) and of linear outputs.
    pub(super) fn initializers(&self, he_init: bool) -> (Initializer, Initializer) {
        if he_init {
            let slope = self.negative_slope;
            let gain = (2.0 / (1.0 + slope * slope)).sqrt();
            (
                Initializer::KaimingNormal { gain, fan_out_only: false },
                Initializer::KaimingNormal { gain: 1.0, fan_out_only: false },
            )
        } else {
            let default =
                Initializer::KaimingUniform { gain: 1.0 / 3f64.sqrt(), fan_out_only: false };
            (default.clone(), default)
        }
    }

    /// Checks the sizes once, so [`init`](Self::init) cannot build a degenerate network.
    pub fn validate(&self) -> crate::error::Result<()> {
        if self.latent == 0 || self.latent > MAX_WIDTH {
            return Err(ModelError::Invalid(format!(
                "latent dimension k = {} is out of range (1 to {MAX_WIDTH})",
                self.latent
            )));
        }
        if !self.negative_slope.is_finite() {
            return Err(ModelError::Invalid("the leaky ReLU slope must be finite".into()));
        }
        match &self.architecture {
            Architecture::Convolutional(c) => {
                let widths = c
                    .encoder_channels
                    .iter()
                    .chain(c.decoder_channels.iter())
                    .chain(c.projection.iter());
                if let Some(w) = widths.into_iter().find(|&&w| w == 0 || w > MAX_WIDTH) {
                    return Err(ModelError::Invalid(format!(
                        "a layer width of {w} is out of range (1 to {MAX_WIDTH})"
                    )));
                }
                if c.residual_blocks > 64 {
                    return Err(ModelError::Invalid(format!(
                        "{} residual blocks is out of range (0 to 64)",
                        c.residual_blocks
                    )));
                }
            }
            Architecture::Slice(s) => {
                if s.directions == 0 || s.directions > 1024 {
                    return Err(ModelError::Invalid(format!(
                        "a slice basis of {} directions is out of range (1 to 1024)",
                        s.directions
                    )));
                }
                if s.components < self.latent || s.components > MAX_WIDTH {
                    return Err(ModelError::Invalid(format!(
                        "{} principal components for k = {} (need k to {MAX_WIDTH})",
                        s.components, self.latent
                    )));
                }
                if s.hidden.is_some_and(|h| h == 0 || h > MAX_WIDTH) || s.harmonics > 64 {
                    return Err(ModelError::Invalid(format!(
                        "a slice MLP width of {:?} or {} harmonics is out of range",
                        s.hidden, s.harmonics
                    )));
                }
                s.augmentation.validate()?;
            }
        }
        Ok(())
    }

    /// [`init`](Self::init) with the weights drawn from `seed`, reproducibly.
    ///
    /// Seeding and drawing happen under one process-wide lock ([`crate::seeded`]): Burn's
    /// generator is shared by the whole process.
    pub fn init_seeded(&self, seed: u64, device: &Device) -> crate::error::Result<Autoencoder> {
        crate::seeded::with_seed(seed, device, || self.build(device))
    }

    /// Builds the network on `device` with freshly initialised weights (and a zero offset),
    /// drawn from the device's generator as it stands (under the lock of [`crate::seeded`]).
    pub fn init(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        crate::seeded::exclusive(|| self.build(device))
    }

    fn build(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.validate()?;
        let model = match &self.architecture {
            Architecture::Convolutional(c) => {
                Autoencoder::Convolutional(Convolutional::new(self, c, device))
            }
            Architecture::Slice(s) => Autoencoder::Slice(SliceNetwork::new(self, s, device)),
        };
        // Burn initialises parameters lazily, on first use, from the device's random generator;
        // drawing them all now, in a fixed order, keeps a seeded run reproducible even when the
        // first use happens in parallel training shards.
        let _ = model.clone().into_record();
        Ok(model)
    }
}

impl TryFrom<serde_json::Value> for AutoencoderConfig {
    type Error = String;

    /// The current format; a retired network's configuration is refused ([`retired`]).
    fn try_from(value: serde_json::Value) -> Result<Self, String> {
        if let Some(what) = retired::retired_network(&value) {
            return Err(retired::message(what));
        }
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Current {
            latent: usize,
            #[serde(default = "default_slope")]
            negative_slope: f64,
            architecture: Architecture,
        }
        fn default_slope() -> f64 {
            0.01
        }
        let c: Current = serde_json::from_value(value.clone()).map_err(|e| e.to_string())?;
        let config = Self {
            latent: c.latent,
            negative_slope: c.negative_slope,
            architecture: c.architecture,
        };
        // A misspelt optional field would otherwise be dropped silently (and its default used).
        let written = serde_json::to_value(&config).map_err(|e| e.to_string())?;
        match unknown_field(&value, &written) {
            Some(field) => Err(format!("unknown field `{field}`")),
            None => Ok(config),
        }
    }
}

/// The first key of `input` (as a dotted path) that `written`, the parsed value written again,
/// lacks: a field the format does not know.
fn unknown_field(input: &serde_json::Value, written: &serde_json::Value) -> Option<String> {
    let (serde_json::Value::Object(input), serde_json::Value::Object(written)) = (input, written)
    else {
        return None;
    };
    input.iter().find_map(|(key, value)| match written.get(key) {
        None => Some(key.clone()),
        Some(w) => unknown_field(value, w).map(|inner| format!("{key}.{inner}")),
    })
}

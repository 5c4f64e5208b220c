//! The autoencoder's configuration: the latent dimension k, the leaky ReLU slope and one
//! [`Architecture`] (Table 1's convolutional network or the `slice` preset's network), with
//! the two presets and the checks that keep [`AutoencoderConfig::init`] from building a
//! degenerate network.

use burn::config::Config;
use serde::{Deserialize, Serialize};

use super::convolutional::{ConvAlgorithm, ConvolutionalConfig};
use super::limits::MAX_WIDTH;
use super::retired;
use super::slice::SliceConfig;
use crate::error::ModelError;
use deepbrdf_data::mapping::MedianReference;

/// PyTorch's default negative slope of the leaky ReLU (the paper does not give one).
pub const NEGATIVE_SLOPE: f64 = 0.01;

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
/// variants here and in [`super::Autoencoder`], each in its own folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Architecture {
    /// Table 1's convolutional encoder and decoder (and narrower variants of it).
    Convolutional(ConvolutionalConfig),
    /// The `slice` preset: one basis for the (theta_h, theta_d) images of every phi_d slice and
    /// colour, a decoder MLP shared by the slices ([`super::slice`]).
    Slice(SliceConfig),
}

impl AutoencoderConfig {
    /// A network of `architecture` with latent dimension `k` and PyTorch's leaky ReLU slope.
    pub fn new(k: usize, architecture: Architecture) -> Self {
        Self { latent: k, negative_slope: NEGATIVE_SLOPE, architecture }
    }

    /// Table 1 exactly, with latent dimension `k`.
    pub fn paper(k: usize) -> Self {
        Self::convolutional(k, ConvolutionalConfig::new())
    }

    /// A convolutional network of latent dimension `k`.
    pub fn convolutional(k: usize, layers: ConvolutionalConfig) -> Self {
        Self::new(k, Architecture::Convolutional(layers))
    }

    /// The `slice` preset ([`super::slice`], [`SliceConfig::preset`]): a basis shared by all
    /// phi_d slices and colours, principal components of the coefficients, MLPs, the
    /// decoder's shared by the slices; small enough to ship.
    pub fn slice(k: usize) -> Self {
        Self::new(k, Architecture::Slice(SliceConfig::preset(k)))
    }

    /// The eq. (1) reference this network is trained with, from the training set's median:
    /// the median as it is, or with its peak flattened where the `slice` configuration asks
    /// ([`SliceConfig::reference_flat_below_deg`]).
    pub fn mapping_reference(&self, median: &MedianReference) -> MedianReference {
        match self.slice_config().and_then(|s| s.reference_flat_below_deg) {
            Some(deg) => median.flattened_below(deg),
            None => median.clone(),
        }
    }

    /// The slice network's settings, if it is one.
    pub fn slice_config(&self) -> Option<&SliceConfig> {
        match &self.architecture {
            Architecture::Slice(s) => Some(s),
            _ => None,
        }
    }

    /// Computes the convolutions with `conv` (the same parameters and values); an error for a
    /// network without convolutions.
    pub fn set_conv(&mut self, conv: ConvAlgorithm) -> crate::error::Result<()> {
        match &mut self.architecture {
            Architecture::Convolutional(layers) => {
                layers.conv = conv;
                Ok(())
            }
            Architecture::Slice(_) => Err(ModelError::Invalid(
                "the slice network has no convolutions to compute another way".into(),
            )),
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

    /// Whether the network standardises per value around its offset
    /// ([`ConvolutionalConfig::standardise`]); never a slice network.
    pub fn standardise(&self) -> bool {
        match &self.architecture {
            Architecture::Convolutional(c) => c.standardise == Some(true),
            Architecture::Slice(_) => false,
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
            Architecture::Convolutional(c) => c.validate(),
            Architecture::Slice(s) => s.validate(self.latent),
        }
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
            NEGATIVE_SLOPE
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

//! Reading what earlier versions wrote: the flat network configuration (a `convolutional` flag,
//! optional `projection`, `spectral_basis` and `spectral_hidden` fields beside each other) and
//! weights recorded before the architectures became variants of [`super::Autoencoder`] (their
//! parameter paths lack the variant's name).

use serde::Deserialize;

use super::config::{Architecture, AutoencoderConfig, ConvolutionalConfig, SpectralConfig};

/// The configuration as versions before the [`Architecture`] enum wrote it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Flat {
    #[serde(default = "defaults::latent")]
    latent: usize,
    #[serde(default)]
    projection: Option<usize>,
    #[serde(default = "defaults::encoder")]
    encoder_channels: [usize; 3],
    #[serde(default = "defaults::residual")]
    residual_blocks: usize,
    #[serde(default = "defaults::decoder")]
    decoder_channels: [usize; 2],
    #[serde(default = "defaults::slope")]
    negative_slope: f64,
    #[serde(default)]
    mean_offset: bool,
    #[serde(default)]
    he_init: bool,
    #[serde(default = "defaults::yes")]
    convolutional: bool,
    #[serde(default)]
    spectral_basis: Option<usize>,
    #[serde(default)]
    spectral_hidden: Option<usize>,
}

/// The defaults of the flat format (Table 1).
mod defaults {
    pub fn latent() -> usize {
        10
    }
    pub fn encoder() -> [usize; 3] {
        [256, 128, 64]
    }
    pub fn residual() -> usize {
        3
    }
    pub fn decoder() -> [usize; 2] {
        [128, 256]
    }
    pub fn slope() -> f64 {
        0.01
    }
    pub fn yes() -> bool {
        true
    }
}

/// Whether `value` is a configuration in the flat format: an object without `architecture`
/// that has one of the flat format's own fields.
pub(crate) fn is_legacy(value: &serde_json::Value) -> bool {
    value.as_object().is_some_and(|o| {
        !o.contains_key("architecture")
            && ["convolutional", "spectral_basis", "encoder_channels", "projection"]
                .iter()
                .any(|k| o.contains_key(*k))
    })
}

/// The flat configuration `value` as an [`AutoencoderConfig`]: a convolutional network without
/// a spectral path, or a spectral one without convolutions (the widths of the convolutions it
/// never built are dropped). A convolutional network with a spectral path beside it (an early
/// experiment, never a preset) is refused with what to do.
pub(super) fn upgrade(value: serde_json::Value) -> Result<AutoencoderConfig, String> {
    let flat: Flat = serde_json::from_value(value).map_err(|e| e.to_string())?;
    let architecture = match (flat.convolutional, flat.spectral_basis) {
        (true, None) => Architecture::Convolutional(
            ConvolutionalConfig::new()
                .with_projection(flat.projection)
                .with_encoder_channels(flat.encoder_channels)
                .with_residual_blocks(flat.residual_blocks)
                .with_decoder_channels(flat.decoder_channels)
                .with_mean_offset(flat.mean_offset)
                .with_he_init(flat.he_init),
        ),
        (false, Some(directions)) if flat.mean_offset => Architecture::Spectral(
            SpectralConfig::new(directions)
                .with_hidden(flat.spectral_hidden)
                .with_he_init(flat.he_init),
        ),
        (true, Some(_)) => {
            return Err("a convolutional network with a spectral path beside it is no longer \
                        supported; train a new model (--preset cpu, or a --config with one \
                        architecture)"
                .into())
        }
        _ => {
            return Err(
                "a network needs convolutions or a spectral path with the mean offset".into()
            )
        }
    };
    Ok(AutoencoderConfig { latent: flat.latent, negative_slope: flat.negative_slope, architecture })
}

/// The variant name [`super::Autoencoder`]'s record paths start with for `config`.
fn variant(config: &AutoencoderConfig) -> &'static str {
    match config.architecture {
        Architecture::Convolutional(_) => "Convolutional",
        Architecture::Spectral(_) => "Spectral",
        Architecture::Slice(_) => "Slice",
    }
}

/// Weights (a burnpack record) of a network of `config` as an earlier version recorded them,
/// with each parameter path prefixed by the variant's name, as [`super::Autoencoder`] records
/// them now. Paths already in the current form are kept.
pub(crate) fn upgrade_record(
    bytes: Vec<u8>,
    config: &AutoencoderConfig,
) -> Result<Vec<u8>, String> {
    let prefix = format!("{}.", variant(config));
    crate::record::rewrite(bytes, true, |name| match name.starts_with(&prefix) {
        true => name,
        false => format!("{prefix}{name}"),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    /// A current record written as earlier versions wrote it: the variant's name (the first
    /// path component) dropped.
    pub(crate) fn strip_variant(bytes: &[u8]) -> Vec<u8> {
        crate::record::rewrite(bytes.to_vec(), true, |name| {
            name.split_once('.').map(|(_, rest)| rest.to_string()).unwrap_or(name)
        })
        .unwrap()
    }
}

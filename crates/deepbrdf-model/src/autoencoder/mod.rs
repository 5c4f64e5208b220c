//! The DeepBRDF autoencoder (Hu et al., CGF 2020, §3.2): encoder f (eq. 2) to k latent values
//! and decoder g (eq. 3) back, one network per [`Architecture`].
//!
//! The input is one BRDF in the §3.2 layout: 540 channels (phi_d x rgb) of 90 x 90 images
//! (rows theta_h, columns theta_d), values in the eq. (1) mapped space. Invalid cells are zeroed
//! at the input (§3.2, footnote †), so the encoder takes the validity mask with the values.
//!
//! - [`Autoencoder::Convolutional`] ([`convolutional`]): Table 1 exactly
//!   ([`AutoencoderConfig::paper`]), or narrower variants of it selectable with a
//!   configuration file, optionally around a fixed offset (the training mean).
//! - [`Autoencoder::Slice`] ([`slice`]): the `slice` preset
//!   ([`AutoencoderConfig::slice`]): one basis for the images of all phi_d slices, a decoder
//!   MLP shared by the slices; small enough to ship.
//!
//! [`artifact`]: the trained network saved with its median reference and provenance.

pub mod artifact;
mod config;
pub mod convolutional;
mod init;
mod limits;
mod retired;
pub mod slice;
pub mod train;

use burn::module::Param;
use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::layout::{SIDE, SLICE_CHANNELS};
use deepbrdf_data::merl::VALUES;

pub use config::{Architecture, AutoencoderConfig, NEGATIVE_SLOPE};
pub use convolutional::{ConvAlgorithm, Convolutional, ConvolutionalConfig, BOTTLENECK_SIDE};
pub(crate) use retired::{message as retired_message, retired_network};
pub use slice::{SliceConfig, SliceNetwork, SLICE_DIRECTIONS};

use crate::error::ModelError;

/// Channels of the §3.2 layout: 180 phi_d slices x 3 colour channels.
pub const INPUT_CHANNELS: usize = SLICE_CHANNELS;
/// Side of each layout image (90 theta_h rows x 90 theta_d columns).
pub const INPUT_SIDE: usize = SIDE;
/// Values of one BRDF in the layout (`540 * 90 * 90`, the MERL table's value count).
pub const INPUT_VALUES: usize = VALUES;

/// The autoencoder of §3.2, one variant per [`Architecture`].
#[derive(Module, Debug)]
pub enum Autoencoder {
    /// Table 1 (and narrower variants).
    Convolutional(Convolutional),
    /// The `slice` preset's network shared across phi_d slices.
    Slice(SliceNetwork),
}

impl AutoencoderConfig {
    /// [`init`](Self::init) with the weights drawn from `seed`, reproducibly.
    ///
    /// Seeding and drawing happen under one process-wide lock ([`crate::seeded`]): Burn's
    /// generator is shared by the whole process.
    pub fn init_seeded(&self, seed: u64, device: &Device) -> crate::error::Result<Autoencoder> {
        crate::seeded::try_with_seed(seed, device, || self.build(device))
    }

    /// Builds the network on `device` with freshly initialised weights (and a zero offset),
    /// drawn from the device's generator as it stands (under the lock of [`crate::seeded`]).
    pub fn init(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        crate::seeded::exclusive(|| self.build(device))
    }

    fn build(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.validate()?;
        let (k, slope) = (self.latent, self.negative_slope);
        let model = match &self.architecture {
            Architecture::Convolutional(c) => {
                Autoencoder::Convolutional(Convolutional::new(k, slope, c, device))
            }
            Architecture::Slice(s) => Autoencoder::Slice(SliceNetwork::new(k, slope, s, device)),
        };
        // Burn initialises parameters lazily, on first use, from the device's random generator;
        // drawing them all now, in a fixed order, keeps a seeded run reproducible even when the
        // first use happens in parallel training shards.
        let _ = model.clone().into_record();
        Ok(model)
    }
}

impl Autoencoder {
    fn offset_ref(&self) -> Option<&Param<Tensor<3>>> {
        match self {
            Self::Convolutional(c) => c.offset.as_ref(),
            Self::Slice(_) => None,
        }
    }

    /// Sets the fixed output offset (the per-value training mean, 540 x 90 x 90 in layout order).
    /// Errors if the configuration has no offset or `values` has the wrong length.
    pub fn with_offset(self, values: &[f32]) -> crate::error::Result<Self> {
        check_layout("an offset", "offset", values, |v| v.is_finite(), "finite")?;
        match self {
            Self::Convolutional(mut c) => {
                let Some(old) = c.offset.take() else {
                    return Err(ModelError::Invalid(
                        "this configuration has no mean offset".into(),
                    ));
                };
                c.offset = Some(fixed_layout(old, values));
                Ok(Self::Convolutional(c))
            }
            Self::Slice(_) => {
                Err(ModelError::Invalid("the slice network has no per-value offset".into()))
            }
        }
    }

    /// Sets the fixed per-value scale (the training spread, 540 x 90 x 90 in layout order,
    /// every value positive). Errors if the configuration does not standardise or `values` has
    /// the wrong length.
    pub fn with_scale(self, values: &[f32]) -> crate::error::Result<Self> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        check_layout("a scale", "scale", values, positive, "positive and finite")?;
        match self {
            Self::Convolutional(mut c) => {
                let Some(old) = c.scale.take() else {
                    return Err(ModelError::Invalid(
                        "this configuration does not standardise per value".into(),
                    ));
                };
                c.scale = Some(fixed_layout(old, values));
                Ok(Self::Convolutional(c))
            }
            Self::Slice(_) => {
                Err(ModelError::Invalid("the slice network has no per-value scale".into()))
            }
        }
    }

    /// The slice network, if the network is one.
    pub fn slice(&self) -> Option<&SliceNetwork> {
        match self {
            Self::Slice(s) => Some(s),
            _ => None,
        }
    }

    /// Sets the slice network's fixed parts ([`SliceNetwork::with_fit`]).
    pub fn with_slice_fit(
        self,
        basis: &[f32],
        mean: &[f32],
        components: &[f32],
    ) -> crate::error::Result<Self> {
        match self {
            Self::Slice(s) => Ok(Self::Slice(s.with_fit(basis, mean, components)?)),
            _ => Err(ModelError::Invalid("this configuration is not a slice network".into())),
        }
    }

    /// The latent dimension k.
    pub fn latent(&self) -> usize {
        match self {
            Self::Convolutional(c) => c.latent,
            Self::Slice(s) => s.latent(),
        }
    }

    /// Encoder f (eq. 2): the k latent values of each BRDF. Invalid cells are zeroed first.
    ///
    /// # Shapes
    /// - input: `[batch, 540, 90, 90]` mapped values
    /// - mask: `[batch, 540, 90, 90]`, 1 for valid cells, 0 for invalid ones
    /// - output: `[batch, k]`
    pub fn encode(&self, input: Tensor<4>, mask: Tensor<4>) -> Tensor<2> {
        let centred = match self.offset_ref() {
            Some(offset) => (input - offset.val().unsqueeze_dim::<4>(0)) * mask, // [batch, 540, 90, 90]
            None => input * mask, // [batch, 540, 90, 90]
        };
        self.encode_centred(centred)
    }

    /// The encoder on inputs already centred and masked: `(input - offset) * mask` (just
    /// `input * mask` without an offset). Training prepares these on the CPU.
    ///
    /// # Shapes
    /// - centred: `[batch, 540, 90, 90]`
    /// - output: `[batch, k]`
    pub fn encode_centred(&self, centred: Tensor<4>) -> Tensor<2> {
        match self {
            Self::Convolutional(c) => c.encode_centred(centred),
            Self::Slice(s) => s.encode_centred(centred),
        }
    }

    /// Decoder g (eq. 3): the mapped BRDF of each latent vector.
    ///
    /// # Shapes
    /// - latent: `[batch, k]`
    /// - output: `[batch, 540, 90, 90]` mapped values (invalid cells are meaningless)
    pub fn decode(&self, latent: Tensor<2>) -> Tensor<4> {
        let y = self.decode_deviation(latent); // [batch, 540, 90, 90]
        match self.offset_ref() {
            Some(offset) => y + offset.val().unsqueeze_dim::<4>(0), // [batch, 540, 90, 90]
            None => y,
        }
    }

    /// The decoder without the fixed offset: the deviation from it (the whole output when the
    /// configuration has no offset). Training compares this with centred targets.
    ///
    /// # Shapes
    /// - latent: `[batch, k]`
    /// - output: `[batch, 540, 90, 90]`
    pub fn decode_deviation(&self, latent: Tensor<2>) -> Tensor<4> {
        match self {
            Self::Convolutional(c) => c.decode_deviation(latent),
            Self::Slice(s) => s.decode_deviation(latent),
        }
    }

    /// The fixed offset, if the configuration has one (540 x 90 x 90 values, layout order).
    pub fn offset(&self) -> Option<Vec<f32>> {
        self.offset_ref().and_then(|p| p.val().into_data().try_into_vec().ok())
    }

    /// g(f(x)): the reconstruction the loss of eq. (4) compares with the input.
    ///
    /// # Shapes
    /// - input, mask: `[batch, 540, 90, 90]`
    /// - output: `[batch, 540, 90, 90]`
    pub fn forward(&self, input: Tensor<4>, mask: Tensor<4>) -> Tensor<4> {
        let latent = self.encode(input, mask); // [batch, k]
        self.decode(latent) // [batch, 540, 90, 90]
    }
}

/// Errors unless `values` is one value per layout cell and `ok` holds for each (`a_what` and
/// `what` name it in the message, `needs` says what `ok` asks).
fn check_layout(
    a_what: &str,
    what: &str,
    values: &[f32],
    ok: impl Fn(f32) -> bool,
    needs: &str,
) -> crate::error::Result<()> {
    if values.len() != INPUT_VALUES {
        return Err(ModelError::Invalid(format!(
            "{a_what} has {INPUT_VALUES} values, got {}",
            values.len()
        )));
    }
    match values.iter().position(|&v| !ok(v)) {
        Some(i) => Err(ModelError::Invalid(format!("{what} value {i} is not {needs}"))),
        None => Ok(()),
    }
}

/// `values` (540 x 90 x 90, layout order) in place of the fixed, untrained layout `old`, on its
/// device.
fn fixed_layout(old: Param<Tensor<3>>, values: &[f32]) -> Param<Tensor<3>> {
    let data = TensorData::new(values.to_vec(), [INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
    old.map(|old| Tensor::from_data(data, &old.device())).set_require_grad(false)
}

#[cfg(test)]
mod tests;

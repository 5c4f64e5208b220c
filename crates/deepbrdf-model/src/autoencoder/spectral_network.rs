//! The `cpu` preset's network (not in the paper): the fixed training mean and the spectral
//! path of [`crate::spectral`] around it.

use burn::module::Param;
use burn::prelude::*;

use super::config::{AutoencoderConfig, SpectralConfig};
use crate::spectral::SpectralPath;

/// The offset mu and the coordinate-space encoder and decoder.
#[derive(Module, Debug)]
pub struct SpectralNetwork {
    /// Fixed per-value offset (the training mean in mapped space), not trained.
    pub(super) offset: Param<Tensor<3>>,
    pub(super) spectral: SpectralPath,
}

impl SpectralNetwork {
    /// The network of `layers` for `config`'s k and slope, with the last layers of its MLPs
    /// at zero (an untrained network is PCA); the basis zero until set, or absent without
    /// `allocate_basis`.
    pub(super) fn new(
        config: &AutoencoderConfig,
        layers: &SpectralConfig,
        allocate_basis: bool,
        device: &Device,
    ) -> Self {
        let (hidden, _) = config.initializers(layers.he_init);
        Self {
            offset: super::zero_offset(device),
            spectral: SpectralPath::new(
                layers.directions,
                config.latent,
                layers.hidden,
                &hidden,
                config.negative_slope,
                allocate_basis,
                device,
            ),
        }
    }

    /// Encoder f (eq. 2) on centred, masked inputs: `z = c[..k] + f(c)`, `c = U (x - mu)`.
    ///
    /// # Shapes
    /// - centred: `[batch, 540, 90, 90]` -> `[batch, k]`
    pub(super) fn encode_centred(&self, centred: Tensor<4>) -> Tensor<2> {
        let batch = centred.dims()[0];
        let flat = centred.reshape([batch, super::INPUT_VALUES]); // [batch, 540*90*90]
        self.spectral.encode(self.spectral.coefficients(flat)) // [batch, k]
    }

    /// Decoder g (eq. 3) without the offset: `U^T ([z, 0] + g(z))`.
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, 540, 90, 90]`
    pub(super) fn decode_deviation(&self, latent: Tensor<2>) -> Tensor<4> {
        let batch = latent.dims()[0];
        let shape = [batch, super::INPUT_CHANNELS, super::INPUT_SIDE, super::INPUT_SIDE];
        self.spectral.expand(self.spectral.decode(latent)).reshape(shape) // [batch, 540, 90, 90]
    }
}

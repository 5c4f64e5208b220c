//! The settings of the `slice` network: the slice basis, the principal components, the MLPs'
//! width and harmonics, the extra training BRDFs, and the checks of their sizes.

use burn::config::Config;

use super::augmentation::AugmentationConfig;
use crate::autoencoder::limits::MAX_WIDTH;
use crate::error::ModelError;

/// The `slice` preset's network ([`super::network`]; not in the paper).
#[derive(Config, Debug, PartialEq)]
pub struct SliceConfig {
    /// M, the directions of the basis shared by the 540 images of a BRDF.
    #[config(default = "SLICE_DIRECTIONS")]
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
    /// How much more the slice basis, and so the training loss and the refinement, weigh the
    /// cells at the highlight's centre: cell weight `1 + e / (1 + theta_h index)`
    /// ([`super::basis::pixel_weights`]); none (as in configurations written without the
    /// field) or 0: unweighted.
    #[config(default = "None")]
    pub centre_emphasis: Option<f64>,
    /// Flatten the eq. (1) reference's peak below this theta_h (degrees) before training
    /// ([`deepbrdf_data::mapping::MedianReference::flattened_below`]); the model keeps the
    /// reference it was trained with. None (as in configurations written without the field):
    /// the median as it is.
    #[config(default = "None")]
    pub reference_flat_below_deg: Option<f64>,
    /// Extra training BRDFs (channel permutations, mixtures), used by the fits of the mean
    /// and components and by training.
    #[config(default = "AugmentationConfig::new()")]
    pub augmentation: AugmentationConfig,
}

/// M of the `slice` preset.
pub const SLICE_DIRECTIONS: usize = 64;

impl SliceConfig {
    /// The `slice` preset's settings for latent dimension `k`: [`SLICE_DIRECTIONS`] basis
    /// directions, max(40, k) principal components, MLPs of width 128, channel permutations
    /// and pairwise mixtures of the training BRDFs ([`AugmentationConfig::preset`]).
    pub fn preset(k: usize) -> Self {
        Self::new()
            .with_directions(SLICE_DIRECTIONS)
            .with_components(k.max(40))
            .with_augmentation(AugmentationConfig::preset())
    }

    /// Checks the sizes for latent dimension `latent`.
    pub fn validate(&self, latent: usize) -> crate::error::Result<()> {
        if self.directions == 0 || self.directions > 1024 {
            return Err(ModelError::Invalid(format!(
                "a slice basis of {} directions is out of range (1 to 1024)",
                self.directions
            )));
        }
        if self.components < latent || self.components > MAX_WIDTH {
            return Err(ModelError::Invalid(format!(
                "{} principal components for k = {latent} (need k to {MAX_WIDTH})",
                self.components
            )));
        }
        if let Some(e) = self.centre_emphasis.filter(|e| !(0.0..=1e6).contains(e)) {
            return Err(ModelError::Invalid(format!(
                "a centre emphasis of {e} is out of range (0 to 1e6)"
            )));
        }
        if let Some(a) = self.reference_flat_below_deg.filter(|a| !(0.0..=90.0).contains(a)) {
            return Err(ModelError::Invalid(format!(
                "a reference flattened below theta_h {a} deg is out of range (0 to 90)"
            )));
        }
        if self.hidden.is_some_and(|h| h == 0 || h > MAX_WIDTH) || self.harmonics > 64 {
            return Err(ModelError::Invalid(format!(
                "a slice MLP width of {:?} or {} harmonics is out of range",
                self.hidden, self.harmonics
            )));
        }
        self.augmentation.validate()
    }
}

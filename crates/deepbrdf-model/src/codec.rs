//! A trained DeepBRDF model in use: a measured BRDF to its k latent values (eq. 2) and back
//! (eq. 3), through the eq. (1) mapping and the §3.2 layout.

use std::path::Path;

use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::augment::fill_missing_layout;
use deepbrdf_data::layout::from_layout;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::merl::grid::valid_mask;
use deepbrdf_data::merl::N_PHI_D;
use deepbrdf_data::network_input::mapped_layout;
use deepbrdf_data::MerlTable;

use crate::autoencoder::artifact::{ModelArtifact, Provenance};
use crate::autoencoder::{
    Autoencoder, AutoencoderConfig, INPUT_CHANNELS, INPUT_SIDE, INPUT_VALUES,
};
use crate::error::{ModelError, Result};
use crate::refine::{image_metric, refine, Refinement};

/// A loaded DeepBRDF model: network, median reference and the MERL grid's validity mask.
#[derive(Debug)]
pub struct DeepBrdf {
    model: Autoencoder,
    artifact: ModelArtifact,
    grid_mask: &'static [bool],
    device: Device,
    /// How the `slice` network's encodings are refined through its decoder ([`crate::refine`]).
    refinement: Refinement,
}

impl DeepBrdf {
    /// Loads a model artifact (or the `model/` inside a training directory) onto `device`.
    pub fn load(path: &Path, device: &Device) -> Result<Self> {
        Self::from_artifact(ModelArtifact::load(path)?, device)
    }

    /// Uses an in-memory artifact on `device`.
    pub fn from_artifact(mut artifact: ModelArtifact, device: &Device) -> Result<Self> {
        let device = device.clone().without_autodiff();
        let model = artifact.take_model(&device)?.valid();
        let refinement = Refinement::default();
        Ok(Self { model, artifact, grid_mask: valid_mask(), device, refinement })
    }

    /// Encodes with `refinement` (a `slice` network's encodings are refined through its
    /// decoder, [`crate::refine`]; [`Refinement::NONE`]: the encoder's latent as it is; other
    /// networks ignore it).
    pub fn with_refinement(mut self, refinement: Refinement) -> Self {
        self.refinement = refinement;
        self
    }

    /// The network.
    pub(crate) fn network(&self) -> &Autoencoder {
        &self.model
    }

    /// The device the network runs on.
    pub(crate) fn device(&self) -> &Device {
        &self.device
    }

    /// The MERL grid's validity mask.
    pub(crate) fn grid_mask(&self) -> &'static [bool] {
        self.grid_mask
    }

    /// k, the number of latent values.
    pub fn k(&self) -> usize {
        self.model.latent()
    }

    /// The artifact's id.
    pub fn id(&self) -> &str {
        self.artifact.id()
    }

    /// The network's configuration.
    pub fn config(&self) -> &AutoencoderConfig {
        self.artifact.config()
    }

    /// How the model was trained.
    pub fn provenance(&self) -> &Provenance {
        self.artifact.provenance()
    }

    /// The eq. (1) reference.
    pub fn reference(&self) -> &MedianReference {
        self.artifact.reference()
    }

    /// Eq. (2): the k latent values of `table`.
    pub fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        let (input, mask) = mapped_layout(table, self.reference());
        self.encode_layout(input, mask)
    }

    /// Eq. (2) from the reduced input of Fig. 2: only the phi_d slices in `kept` are used; each
    /// missing slice is filled from its nearest kept one (§3.2) before encoding.
    pub fn encode_partial(&self, table: &MerlTable, kept: &[usize]) -> Result<Vec<f32>> {
        let (input, mask) = mapped_layout(table, self.reference());
        self.encode_partial_layout(input, mask, kept)
    }

    /// [`DeepBrdf::encode_partial`] on a mapped layout and its mask (as
    /// [`DeepBrdf::encode_layout`] takes them): the slices not in `kept` are filled from their
    /// nearest kept one (whole image slices, §3.2) and invalid cells zeroed again.
    pub fn encode_partial_layout(
        &self,
        mut input: Vec<f32>,
        mask: Vec<f32>,
        kept: &[usize],
    ) -> Result<Vec<f32>> {
        if kept.is_empty() || kept.iter().any(|&k| k >= N_PHI_D) {
            return Err(ModelError::Invalid(format!(
                "kept slices must be a non-empty subset of 0..{N_PHI_D}"
            )));
        }
        if input.len() != INPUT_VALUES || mask.len() != INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "encoding needs {INPUT_VALUES} layout values and mask entries"
            )));
        }
        fill_missing_layout(&mut input, kept);
        for (v, m) in input.iter_mut().zip(&mask) {
            *v *= m;
        }
        self.encode_layout(input, mask)
    }

    /// Eq. (2) on a mapped layout and its mask (both `540 * 90 * 90` values).
    pub fn encode_layout(&self, input: Vec<f32>, mask: Vec<f32>) -> Result<Vec<f32>> {
        if input.len() != INPUT_VALUES || mask.len() != INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "encoding needs {INPUT_VALUES} layout values and mask entries"
            )));
        }
        if let Some(net) = self.model.slice().filter(|_| self.refinement.iterations > 0) {
            return self.encode_refined(net, input, mask);
        }
        let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
        let input = Tensor::from_data(TensorData::new(input, shape), &self.device);
        let mask = Tensor::from_data(TensorData::new(mask, shape), &self.device);
        let latent = self.model.encode(input, mask); // [1, k]
        let latent = crate::read_back::values(latent, "the latent vector")?;
        if let Some(i) = latent.iter().position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("latent value {i} is not finite")));
        }
        Ok(latent)
    }

    /// A `slice` network's encoding of a mapped layout and its mask, refined through its decoder
    /// from the encoder's latent and the principal-component latent ([`crate::refine`]).
    fn encode_refined(
        &self,
        net: &crate::autoencoder::SliceNetwork,
        mut input: Vec<f32>,
        mask: Vec<f32>,
    ) -> Result<Vec<f32>> {
        for (v, m) in input.iter_mut().zip(&mask) {
            *v *= m;
        }
        let power = self.refinement.radiance_power;
        let metric = match power == 0.0 {
            true => None,
            false => {
                let basis = net.basis_values()?;
                let reference = self.reference().values();
                Some(image_metric(&input, &mask, reference, &basis, power)?)
            }
        };
        let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
        let masked = Tensor::from_data(TensorData::new(input, shape), &self.device);
        let a = net.coefficients(masked); // [1, 540 M]
        let encoded =
            crate::read_back::values(net.encode_coefficients(a.clone()), "the latent vector")?;
        let linear = crate::read_back::values(net.linear_latent(a.clone()), "the latent vector")?;
        let target = crate::read_back::values(a, "the input's coefficients")?;
        if let Some(i) = target.iter().chain(&encoded).chain(&linear).position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("encoding value {i} is not finite")));
        }
        let starts = [encoded, linear];
        let (latent, _) =
            refine(net, &target, &starts, self.refinement, metric.as_ref(), &self.device)?;
        Ok(latent)
    }

    /// Eq. (3) in mapped space: the network's output for `latent`, `540 * 90 * 90` values in
    /// the §3.2 layout (invalid cells hold whatever the network produced).
    pub fn decode_layout(&self, latent: &[f32]) -> Result<Vec<f32>> {
        if latent.len() != self.k() {
            return Err(ModelError::Invalid(format!(
                "this model has k = {} latent values, got {}",
                self.k(),
                latent.len()
            )));
        }
        if let Some(i) = latent.iter().position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("latent value {i} is not finite")));
        }
        let z =
            Tensor::from_data(TensorData::new(latent.to_vec(), [1, latent.len()]), &self.device);
        let out = self.model.decode(z); // [1, 540, 90, 90]
        crate::read_back::values(out, "the decoded layout")
    }

    /// Eq. (3): the full MERL table of `latent` (network, inverse layout, inverse eq. (1) on the
    /// grid's valid cells; invalid cells negative as in MERL files).
    pub fn decode(&self, latent: &[f32]) -> Result<MerlTable> {
        let mapped = from_layout(&self.decode_layout(latent)?);
        Ok(self.reference().unmap(&mapped, self.grid_mask)?)
    }

    /// Encode then decode.
    pub fn reconstruct(&self, table: &MerlTable) -> Result<MerlTable> {
        self.decode(&self.encode(table)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autoencoder::artifact::Provenance;
    use crate::device::DeviceKind;
    use deepbrdf_data::merl::{read_merl, write_merl, CELLS, VALUES};

    fn codec() -> DeepBrdf {
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let layers = crate::autoencoder::ConvolutionalConfig::new()
            .with_projection(Some(1))
            .with_encoder_channels([1, 1, 1])
            .with_residual_blocks(0)
            .with_decoder_channels([1, 1])
            .with_mean_offset(true);
        let config = AutoencoderConfig::convolutional(3, layers);
        let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| 0.5 + 0.1 * ((i % 11) as f32)).collect();
        let model = config.init_seeded(3, &device).unwrap().with_offset(&offset).unwrap();
        let provenance = Provenance::untrained("synthetic", 3);
        let reference = MedianReference::from_values(vec![0.2; VALUES]).unwrap();
        let artifact = ModelArtifact::new(config, provenance, &model, reference).unwrap();
        DeepBrdf::from_artifact(artifact, &device).unwrap()
    }

    #[test]
    fn decoding_gives_a_valid_merl_table_that_survives_a_file() {
        let codec = codec();
        let table = codec.decode(&[0.1, -0.2, 0.3]).unwrap();
        let mask = valid_mask().to_vec();
        for (cell, &valid) in mask.iter().enumerate() {
            let rgb = [0, 1, 2].map(|c| table.values()[c * CELLS + cell]);
            if valid {
                assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0), "cell {cell}: {rgb:?}");
            } else {
                assert!(rgb.iter().all(|v| *v < 0.0), "cell {cell}: {rgb:?}");
            }
        }
        assert_eq!(table.mask(), mask);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.binary");
        write_merl(&table, &path).unwrap();
        assert_eq!(read_merl(&path).unwrap().mask(), mask);
        assert!(codec.decode(&[0.0; 2]).is_err());
        assert!(codec.decode(&[0.0, f32::NAN, 0.0]).is_err());
    }

    #[test]
    fn encoding_full_and_partial_inputs() {
        let codec = codec();
        let table = MerlTable::from_fn(|h, d, p| {
            let v = 0.05 + 0.001 * (h + d) as f32 + 0.0001 * p as f32;
            [v, 2.0 * v, 3.0 * v]
        });
        let full = codec.encode(&table).unwrap();
        assert_eq!(full.len(), 3);
        let all: Vec<usize> = (0..N_PHI_D).collect();
        assert_eq!(codec.encode_partial(&table, &all).unwrap(), full);
        let ninth: Vec<usize> = (0..N_PHI_D).step_by(9).collect();
        let partial = codec.encode_partial(&table, &ninth).unwrap();
        assert_ne!(partial, full);
        assert!(codec.encode_partial(&table, &[]).is_err());
        assert!(codec.encode_partial(&table, &[180]).is_err());
        assert_eq!(codec.reconstruct(&table).unwrap().mask(), valid_mask());
    }
}

//! A trained DeepBRDF model in use: a measured BRDF to its k latent values (eq. 2) and back
//! (eq. 3), through the eq. (1) mapping and the §3.2 layout.

use std::path::Path;
use std::sync::Arc;

use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::augment::fill_missing_layout;
use deepbrdf_data::layout::from_layout;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::merl::grid::valid_mask;
use deepbrdf_data::merl::N_PHI_D;
use deepbrdf_data::network_input::mapped_layout;
use deepbrdf_data::MerlTable;

use crate::artifact::{ModelArtifact, Provenance};
use crate::autoencoder::{
    Autoencoder, AutoencoderConfig, INPUT_CHANNELS, INPUT_SIDE, INPUT_VALUES,
};
use crate::compact::CompactBasis;
use crate::error::{ModelError, Result};
use crate::refine::{image_metric, refine, Refinement};

/// A loaded DeepBRDF model: network, median reference and the MERL grid's validity mask.
///
/// A spectral-only network (the `cpu` preset) keeps its basis as a [`CompactBasis`] (support
/// only, f16) instead of in the network: encoding and decoding read 0.67 GB instead of 1.7 GB.
#[derive(Debug)]
pub struct DeepBrdf {
    model: Autoencoder,
    /// Shared with other models holding the same basis ([`DeepBrdf::share_basis`]).
    basis: Option<Arc<CompactBasis>>,
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
        let (model, compact) = artifact.take_model(&device)?;
        let mut model = model.valid();
        let basis = match compact {
            Some(basis) => Some(Arc::new(basis)),
            // A version 1 model: the f32 basis is in the network.
            None if artifact.config().spectral_config().is_some() => {
                Some(Arc::new(CompactBasis::take_from(&mut model)?))
            }
            None => None,
        };
        let refinement = Refinement::default();
        Ok(Self { model, basis, artifact, grid_mask: valid_mask(), device, refinement })
    }

    /// Uses `other`'s compact basis instead of this model's own when the two are equal (the
    /// models of one training set at different k fit the same basis: one copy, 0.67 GB for
    /// the `cpu` preset, instead of one per model). Returns whether it is shared now.
    pub fn share_basis(&mut self, other: &DeepBrdf) -> bool {
        match (&mut self.basis, &other.basis) {
            (Some(mine), Some(theirs)) if Arc::ptr_eq(mine, theirs) => true,
            (Some(mine), Some(theirs)) if **mine == **theirs => {
                *mine = Arc::clone(theirs);
                true
            }
            _ => false,
        }
    }

    /// Encodes with `refinement` (a `slice` network's encodings are refined through its
    /// decoder, [`crate::refine`]; [`Refinement::NONE`]: the encoder's latent as it is; other
    /// networks ignore it).
    pub fn with_refinement(mut self, refinement: Refinement) -> Self {
        self.refinement = refinement;
        self
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
        let latent = match (&self.basis, self.model.spectral()) {
            (Some(basis), Some(path)) => {
                let c = basis.coefficients(&input, &mask)?;
                let c = Tensor::from_data(TensorData::new(c, [1, basis.size()]), &self.device);
                path.encode(c) // [1, k]
            }
            _ => {
                if let Some(net) = self.model.slice().filter(|_| self.refinement.iterations > 0) {
                    return self.encode_refined(net, input, mask);
                }
                let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
                let input = Tensor::from_data(TensorData::new(input, shape), &self.device);
                let mask = Tensor::from_data(TensorData::new(mask, shape), &self.device);
                self.model.encode(input, mask) // [1, k]
            }
        };
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
        net: &crate::autoencoder::slice_network::SliceNetwork,
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
        match (&self.basis, self.model.spectral()) {
            (Some(basis), Some(path)) => {
                let c = crate::read_back::values(path.decode(z), "the decoded coefficients")?; // [1, K]
                basis.expand(&c)
            }
            _ => {
                let out = self.model.decode(z); // [1, 540, 90, 90]
                crate::read_back::values(out, "the decoded layout")
            }
        }
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
    use crate::artifact::{Provenance, BASIS_FILE, WEIGHTS_FILE};
    use crate::device::DeviceKind;
    use deepbrdf_data::layout::mask_layout;
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

    fn noise(seed: usize, i: usize) -> f32 {
        ((i * 7919 + seed * 104729) % 1000) as f32 / 1000.0
    }

    /// K = 3 directions of seeded pseudo-random values on the grid's valid cells, an offset
    /// there, k = 2; with the offset.
    fn spectral_network(device: &Device) -> (AutoencoderConfig, Autoencoder, Vec<f32>) {
        let config = AutoencoderConfig::spectral(2, 3, Some(4));
        let valid = mask_layout(valid_mask());
        let basis: Vec<f32> = (0..3 * INPUT_VALUES)
            .map(|i| valid[i % INPUT_VALUES] * (noise(1, i) - 0.5) * 1e-3)
            .collect();
        let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| valid[i] * (noise(2, i) - 0.3)).collect();
        let network = config
            .init_seeded(4, device)
            .unwrap()
            .with_offset(&offset)
            .unwrap()
            .with_basis(basis)
            .unwrap();
        (config, network, offset)
    }

    #[test]
    fn spectral_models_save_their_basis_compact_and_version_1_models_still_load() {
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let (config, network, _) = spectral_network(&device);
        let reference = MedianReference::from_values(vec![0.2; VALUES]).unwrap();
        let provenance = Provenance::untrained("synthetic", 4);
        let compact =
            ModelArtifact::new(config.clone(), provenance.clone(), &network, reference.clone())
                .unwrap();
        let v1 = ModelArtifact::new_uncompacted(config, provenance, &network, reference).unwrap();
        assert!(compact.model(&device).is_err(), "no f32 network from an f16 basis");
        let root = tempfile::tempdir().unwrap();
        let (a, b) = (root.path().join("compact"), root.path().join("v1"));
        compact.save(&a).unwrap();
        v1.save(&b).unwrap();
        let size = |p: std::path::PathBuf| std::fs::metadata(p).unwrap().len();
        // The weights keep the f32 offset (one layout) and the MLPs, not the 3 basis rows.
        let one_layout = 4 * INPUT_VALUES as u64;
        assert!(size(a.join(WEIGHTS_FILE)) < one_layout + (1 << 20), "the basis left the weights");
        assert!(size(b.join(WEIGHTS_FILE)) > 4 * one_layout);
        assert!(a.join(BASIS_FILE).is_file() && !b.join(BASIS_FILE).exists());
        // Both decode through the same compact basis: the same values.
        let z = [0.3f32, -0.6];
        let from_a = DeepBrdf::load(&a, &device).unwrap().decode_layout(&z).unwrap();
        let from_b = DeepBrdf::load(&b, &device).unwrap().decode_layout(&z).unwrap();
        let in_memory = DeepBrdf::from_artifact(compact, &device).unwrap();
        assert_eq!(from_a, from_b);
        assert_eq!(from_a, in_memory.decode_layout(&z).unwrap());
        // A damaged basis file is named.
        let mut bytes = std::fs::read(a.join(BASIS_FILE)).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(a.join(BASIS_FILE), bytes).unwrap();
        let err = DeepBrdf::load(&a, &device).unwrap_err().to_string();
        assert!(err.contains(BASIS_FILE) && err.contains("not belong"), "{err}");
    }

    #[test]
    fn a_spectral_codec_matches_its_network_within_half_precision() {
        // The codec's compact f16 basis against the network's own f32 matmuls.
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let (config, network, offset) = spectral_network(&device);
        let valid = mask_layout(valid_mask());
        let provenance = Provenance::untrained("synthetic", 4);
        let reference = MedianReference::from_values(vec![0.2; VALUES]).unwrap();
        let artifact = ModelArtifact::new(config, provenance, &network, reference).unwrap();
        let codec = DeepBrdf::from_artifact(artifact, &device).unwrap();
        let z = [0.3f32, -0.6];
        let got = codec.decode_layout(&z).unwrap();
        let tensor = Tensor::<2>::from_data(TensorData::new(z.to_vec(), [1, 2]), &device);
        let expected: Vec<f32> = network.decode(tensor).into_data().try_into_vec().unwrap();
        let worst = got.iter().zip(&expected).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
        // |z| * |U| <= 0.6 * 5e-4 per direction: f16 rounding moves the sum by < 1e-6.
        assert!(worst < 1e-6, "decode differs by {worst}");
        let input: Vec<f32> = (0..INPUT_VALUES).map(|i| offset[i] + noise(3, i)).collect();
        let got = codec.encode_layout(input.clone(), valid.clone()).unwrap();
        let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
        let expected: Vec<f32> = network
            .encode(
                Tensor::from_data(TensorData::new(input, shape), &device),
                Tensor::from_data(TensorData::new(valid, shape), &device),
            )
            .into_data()
            .try_into_vec()
            .unwrap();
        for (a, b) in got.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-3 * b.abs().max(1e-2), "encode: {got:?} vs {expected:?}");
        }
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

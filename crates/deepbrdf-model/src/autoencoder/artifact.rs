//! The saved DeepBRDF model: a directory holding everything needed to use a trained autoencoder,
//! in the container every saved network shares ([`crate::artifact`]), with checksums that tie
//! the parts together.
//!
//! ```text
//! model/
//!   model.json             id, network configuration, training provenance, part checksums
//!   weights.bpk            the network's parameters (burnpack, Burn's record format), written
//!                          packed (`deepbrdf_data::packed`, lossless); a plain record is read too
//!   median_reference.bin   the eq. (1) reference of the training data (deepbrdf-data format,
//!                          written zstd-compressed)
//! ```
//!
//! A directory of a retired network (with the `basis.f16` of the retired `cpu` preset, or the
//! flat configuration of earlier versions) is refused with what to do
//! ([`crate::autoencoder::retired_network`]). The id is a SHA-256 over the configuration, the provenance and the checksums of the parts,
//! so editing `model.json` or swapping in the weights or reference of another model is detected
//! when loading. The directory is written beside its destination and renamed into place.

use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

use burn::prelude::*;
use deepbrdf_data::mapping::MedianReference;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::artifact::files::{read_limited, read_weights, write_manifest, write_weights};
use crate::artifact::{check_id, dir, load_weights, network_bytes, parse_manifest, Part};
use crate::autoencoder::train::Trained;
use crate::autoencoder::{retired_network, Autoencoder, AutoencoderConfig};
use crate::error::{ModelError, Result};

/// File name of the manifest.
pub const MANIFEST_FILE: &str = "model.json";
/// File name of the weights.
pub const WEIGHTS_FILE: &str = "weights.bpk";
/// File name of the median reference.
pub const REFERENCE_FILE: &str = "median_reference.bin";
/// Name of the artifact directory that training writes inside its output directory.
pub const MODEL_DIR: &str = "model";
const VERSION: u32 = 2;

/// How a model was trained (§3.2's settings and the data), recorded with the model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The data source's label (e.g. "merl").
    pub data_label: String,
    /// The training BRDFs' names.
    pub materials: Vec<String>,
    /// Digest of the training data (see `TrainingSet::fingerprint`).
    pub data_fingerprint: String,
    /// The full training configuration (network, optimizer, schedule, seed).
    pub train_config: serde_json::Value,
    /// Seed of the run.
    pub seed: u64,
    /// Epochs trained.
    pub epochs: usize,
    /// The last epoch's mean eq. (4) loss.
    pub final_loss: f64,
    /// Mean over the training BRDFs of their mapped-space MSE after training.
    pub final_mse: f64,
    /// Seconds of training.
    pub train_seconds: f64,
    /// The device it was trained on.
    pub device: String,
}

impl Provenance {
    /// Whether the material `name` (as the training data named it, or `collection/name` as a
    /// bundled material is named) is one of the training BRDFs.
    pub fn trained_on(&self, name: &str) -> bool {
        self.materials.iter().any(|t| name == t || name.ends_with(&format!("/{t}")))
    }

    /// The provenance of a network that was not trained on data (synthetic weights for tests and
    /// benchmarks), labelled `label`.
    pub fn untrained(label: &str, seed: u64) -> Self {
        Self {
            data_label: label.into(),
            materials: Vec::new(),
            data_fingerprint: String::new(),
            train_config: serde_json::Value::Null,
            seed,
            epochs: 0,
            final_loss: 0.0,
            final_mse: 0.0,
            train_seconds: 0.0,
            device: String::new(),
        }
    }
}

/// The content of `model.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Manifest {
    format: String,
    version: u32,
    id: String,
    /// The network's configuration as it was written (and hashed into the id).
    config: serde_json::Value,
    provenance: Provenance,
    weights: Part,
    reference: Part,
    /// Only in models of the retired `cpu` preset: refused when present.
    #[serde(default, skip_serializing)]
    basis: Option<serde_json::Value>,
}

impl crate::artifact::Manifest for Manifest {
    const FORMAT: &'static str = "deepbrdf-model";
    const VERSIONS: RangeInclusive<u32> = 1..=VERSION;
    const WHAT: &'static str = "a DeepBRDF model";

    fn format(&self) -> (&str, u32) {
        (&self.format, self.version)
    }

    fn id(&self) -> &str {
        &self.id
    }

    fn content(&self) -> serde_json::Value {
        serde_json::json!({
            "config": self.config,
            "provenance": self.provenance,
            "weights": self.weights,
            "reference": self.reference,
        })
    }
}

/// A trained model with its median reference and provenance, in memory.
#[derive(Debug, Clone)]
pub struct ModelArtifact {
    config: AutoencoderConfig,
    manifest: Manifest,
    weights: Vec<u8>,
    reference: MedianReference,
}

impl ModelArtifact {
    /// Bundles a trained network with the reference its training data was mapped with.
    pub fn from_trained(
        trained: Trained,
        reference: MedianReference,
        data_label: &str,
        materials: &[String],
        device: &Device,
    ) -> Result<Self> {
        let train_config = serde_json::to_value(&trained.config)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the configuration: {e}")))?;
        let provenance = Provenance {
            data_label: data_label.to_string(),
            materials: materials.to_vec(),
            data_fingerprint: trained.data_fingerprint.clone(),
            train_config,
            seed: trained.config.seed,
            epochs: trained.log.len(),
            final_loss: trained.final_loss(),
            final_mse: trained.mean_mse(),
            train_seconds: trained.seconds,
            device: format!("{device:?}"),
        };
        Self::assemble(trained.config.model.clone(), provenance, trained.model, reference)
    }

    /// Bundles a network, its configuration, reference and provenance.
    pub fn new(
        config: AutoencoderConfig,
        provenance: Provenance,
        model: &Autoencoder,
        reference: MedianReference,
    ) -> Result<Self> {
        Self::assemble(config, provenance, model.clone(), reference)
    }

    fn assemble(
        config: AutoencoderConfig,
        provenance: Provenance,
        model: Autoencoder,
        reference: MedianReference,
    ) -> Result<Self> {
        use crate::artifact::Manifest as _;
        let weights = network_bytes(model)?;
        let mut manifest = Manifest {
            format: <Manifest as crate::artifact::Manifest>::FORMAT.into(),
            version: VERSION,
            id: String::new(),
            config: serde_json::to_value(&config).map_err(|e| {
                ModelError::Invalid(format!("cannot serialise the configuration: {e}"))
            })?,
            provenance,
            weights: Part::of(&weights, WEIGHTS_FILE),
            reference: reference_part(&reference),
            basis: None,
        };
        manifest.id = manifest.computed_id();
        Ok(Self { config, manifest, weights, reference })
    }

    /// The id tying configuration, provenance, weights and reference together.
    pub fn id(&self) -> &str {
        &self.manifest.id
    }

    /// The network's configuration.
    pub fn config(&self) -> &AutoencoderConfig {
        &self.config
    }

    /// How the model was trained.
    pub fn provenance(&self) -> &Provenance {
        &self.manifest.provenance
    }

    /// The eq. (1) reference the network's inputs are mapped with.
    pub fn reference(&self) -> &MedianReference {
        &self.reference
    }

    /// Builds the network on `device` and loads the weights into it.
    pub fn model(&self, device: &Device) -> Result<Autoencoder> {
        load_weights(self.config.init(device)?, self.weights.clone())
    }

    /// The network, without keeping a copy of the weights: the artifact keeps its
    /// configuration, provenance, reference and id, and can no longer be saved or loaded into
    /// a network again.
    pub fn take_model(&mut self, device: &Device) -> Result<Autoencoder> {
        let weights = std::mem::take(&mut self.weights);
        load_weights(self.config.init(device)?, weights)
    }

    /// Writes the artifact directory `dir` (created beside it, then renamed into place).
    /// An existing `dir` is replaced only if it is itself a model artifact.
    pub fn save(&self, dir: &Path) -> Result<()> {
        if self.weights.is_empty() {
            return Err(ModelError::Invalid("this artifact's weights were handed over".into()));
        }
        dir::save(dir, MANIFEST_FILE, "a DeepBRDF model", |tmp| {
            write_weights(&tmp.join(WEIGHTS_FILE), &self.weights)?;
            self.reference.save_compressed(tmp.join(REFERENCE_FILE))?;
            write_manifest(&tmp.join(MANIFEST_FILE), &self.manifest)
        })
    }

    /// Loads an artifact directory, or a training output directory holding one in `model/`,
    /// checking that configuration, provenance, weights and reference belong together.
    pub fn load(path: &Path) -> Result<Self> {
        let dir = resolve_dir(path)?;
        let manifest_path = dir.join(MANIFEST_FILE);
        let text = read_limited(&manifest_path, 64 << 20)?;
        let (manifest, config) = parse(&manifest_path, &text)?;
        let owner = format!("model {}", manifest.id);
        let weights_path = dir.join(WEIGHTS_FILE);
        let weights = read_weights(&weights_path, 4 << 30)?;
        manifest.weights.check(&weights_path, &weights, "these weights", &owner)?;
        let reference_path = dir.join(REFERENCE_FILE);
        let reference = MedianReference::load(&reference_path)?;
        if reference_part(&reference) != manifest.reference {
            return Err(ModelError::mismatch(
                &reference_path,
                format!("this median reference does not belong to {owner} (checksum differs)"),
            ));
        }
        check_id(&manifest_path, &manifest)?;
        Ok(Self { config, manifest, weights, reference })
    }
}

/// Parses and checks `model.json` (its bytes `text`, read from `path`): format, version and a
/// valid network configuration (sizes in range, so nothing is allocated for an absurd one).
fn parse(path: &Path, text: &[u8]) -> Result<(Manifest, AutoencoderConfig)> {
    let manifest: Manifest = parse_manifest(path, text)?;
    let retired = match manifest.basis.is_some() {
        true => Some("the spectral network of the retired `cpu` preset, with its basis.f16"),
        false => retired_network(&manifest.config),
    };
    if let Some(what) = retired {
        let dir = path.parent().unwrap_or(path);
        return Err(ModelError::format(dir, crate::autoencoder::retired_message(what)));
    }
    let config = AutoencoderConfig::try_from(manifest.config.clone())
        .map_err(|e| ModelError::format(path, format!("bad network configuration: {e}")))?;
    config.validate()?;
    Ok((manifest, config))
}

/// The reference's checksum is taken over its values (little-endian f32), not over the file,
/// whose own format and checksum belong to `deepbrdf-data`.
fn reference_part(reference: &MedianReference) -> Part {
    let mut hasher = Sha256::new();
    for v in reference.values() {
        hasher.update(v.to_le_bytes());
    }
    Part {
        file: REFERENCE_FILE.into(),
        bytes: 4 * reference.values().len() as u64,
        sha256: hex::encode(hasher.finalize()),
    }
}

/// `path` itself if it holds a manifest, else `path/model` if that does.
pub fn resolve_dir(path: &Path) -> Result<PathBuf> {
    dir::resolve(path, MANIFEST_FILE, MODEL_DIR, "a DeepBRDF model")
}

#[cfg(test)]
#[path = "artifact_fuzz.rs"]
mod fuzz;

#[cfg(test)]
#[path = "artifact_tests.rs"]
mod tests;

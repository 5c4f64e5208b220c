//! The self-contained model artifact: a directory holding everything needed to use a trained
//! DeepBRDF network, with checksums that tie the parts together.
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

use std::fs;
use std::path::{Path, PathBuf};

use burn::prelude::*;
use deepbrdf_data::mapping::MedianReference;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::atomic::{check_format, read_limited, read_weights, write_manifest, write_weights};
use crate::autoencoder::train::Trained;
use crate::autoencoder::{retired_network, Autoencoder, AutoencoderConfig};
use crate::error::{ModelError, Result};
use deepbrdf_data::files::sync_dir_of;

/// File name of the manifest.
pub const MANIFEST_FILE: &str = "model.json";
/// File name of the weights.
pub const WEIGHTS_FILE: &str = "weights.bpk";
/// File name of the median reference.
pub const REFERENCE_FILE: &str = "median_reference.bin";
/// Name of the artifact directory that training writes inside its output directory.
pub const MODEL_DIR: &str = "model";
const FORMAT: &str = "deepbrdf-model";
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

/// Checksum of one part file (also of the networks saved beside a model: [`crate::recovery`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Part {
    pub(crate) file: String,
    pub(crate) bytes: u64,
    pub(crate) sha256: String,
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

/// The checksums of an artifact's parts, computed once.
#[derive(Debug, Clone)]
struct Parts {
    weights: Part,
    reference: Part,
}

/// A trained model with its median reference and provenance, in memory.
#[derive(Debug, Clone)]
pub struct ModelArtifact {
    config: AutoencoderConfig,
    /// `config` in the form the manifest holds and the id covers (see [`Manifest::config`]).
    config_json: serde_json::Value,
    provenance: Provenance,
    weights: Vec<u8>,
    reference: MedianReference,
    parts: Parts,
    id: String,
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
        let weights = model
            .into_record()
            .into_bytes()
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the weights: {e}")))?
            .to_vec();
        // Without Burn's random parameter ids, the same network has the same bytes.
        let weights = crate::record::rewrite(weights, false, |name| name)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the weights: {e}")))?;
        let parts = Parts {
            weights: part_of(&weights, WEIGHTS_FILE),
            reference: reference_part(&reference),
        };
        let config_json = serde_json::to_value(&config)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the configuration: {e}")))?;
        let id = manifest_id(&config_json, &provenance, &parts);
        Ok(Self { config, config_json, provenance, weights, reference, parts, id })
    }

    /// The id tying configuration, provenance, weights and reference together.
    pub fn id(&self) -> &str {
        &self.id
    }

    /// The network's configuration.
    pub fn config(&self) -> &AutoencoderConfig {
        &self.config
    }

    /// How the model was trained.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
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
        save_dir(dir, MANIFEST_FILE, "a DeepBRDF model", |tmp| self.write_parts(tmp))
    }

    fn write_parts(&self, dir: &Path) -> Result<()> {
        write_weights(&dir.join(WEIGHTS_FILE), &self.weights)?;
        self.reference.save_compressed(dir.join(REFERENCE_FILE))?;
        let manifest = Manifest {
            format: FORMAT.into(),
            version: VERSION,
            id: self.id.clone(),
            config: self.config_json.clone(),
            provenance: self.provenance.clone(),
            weights: self.parts.weights.clone(),
            reference: self.parts.reference.clone(),
            basis: None,
        };
        write_manifest(&dir.join(MANIFEST_FILE), &manifest)
    }

    /// Loads an artifact directory, or a training output directory holding one in `model/`,
    /// checking that configuration, provenance, weights and reference belong together.
    pub fn load(path: &Path) -> Result<Self> {
        let dir = resolve_dir(path)?;
        let manifest_path = dir.join(MANIFEST_FILE);
        let text = read_limited(&manifest_path, 64 << 20)?;
        let (manifest, config) = parse_manifest(&manifest_path, &text)?;
        let weights_path = dir.join(WEIGHTS_FILE);
        let weights = read_weights(&weights_path, 4 << 30)?;
        if part_of(&weights, WEIGHTS_FILE) != manifest.weights {
            return Err(ModelError::mismatch(
                &weights_path,
                format!("these weights do not belong to model {} (checksum differs)", manifest.id),
            ));
        }
        let reference_path = dir.join(REFERENCE_FILE);
        let reference = MedianReference::load(&reference_path)?;
        if reference_part(&reference) != manifest.reference {
            return Err(ModelError::mismatch(
                &reference_path,
                format!(
                    "this median reference does not belong to model {} (checksum differs)",
                    manifest.id
                ),
            ));
        }
        let parts = Parts { weights: manifest.weights, reference: manifest.reference };
        if manifest_id(&manifest.config, &manifest.provenance, &parts) != manifest.id {
            return Err(ModelError::mismatch(
                &manifest_path,
                "the manifest was edited or damaged (its id does not match its content)",
            ));
        }
        Ok(Self {
            config,
            config_json: manifest.config,
            provenance: manifest.provenance,
            weights,
            reference,
            parts,
            id: manifest.id,
        })
    }
}

/// Parses and checks `model.json` (its bytes `text`, read from `path`): format, version and a
/// valid network configuration (sizes in range, so nothing is allocated for an absurd one).
fn parse_manifest(path: &Path, text: &[u8]) -> Result<(Manifest, AutoencoderConfig)> {
    let manifest: Manifest = serde_json::from_slice(text)
        .map_err(|e| ModelError::format(path, format!("not a DeepBRDF model manifest: {e}")))?;
    check_format(path, (&manifest.format, manifest.version), FORMAT, 1..=VERSION)?;
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

/// The id over configuration, provenance and the parts' checksums.
fn manifest_id(config: &serde_json::Value, provenance: &Provenance, parts: &Parts) -> String {
    let content = serde_json::json!({
        "config": config,
        "provenance": provenance,
        "weights": parts.weights,
        "reference": parts.reference,
    });
    let digest = Sha256::digest(canonical(content).to_string().as_bytes());
    hex::encode(&digest[..16])
}

/// Loads burnpack `weights` into `network` (any network).
pub(crate) fn load_weights<M: Module>(network: M, weights: Vec<u8>) -> Result<M> {
    let bad = |e: burn::store::RecordError| {
        ModelError::Invalid(format!("the weights do not fit the configuration: {e}"))
    };
    let record = crate::record::float_record(weights).map_err(|e| {
        ModelError::Invalid(format!("the weights do not fit the configuration: {e}"))
    })?;
    network.try_load_record(record).map_err(bad)
}

/// `value` with every non-integer number replaced by its 10-significant-digit text, so the id
/// survives a JSON round trip (serde_json may parse a printed f64 one unit in the last place
/// away) while any real edit still changes it.
pub(crate) fn canonical(value: serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match value {
        Value::Number(n) if !(n.is_i64() || n.is_u64()) => {
            Value::String(format!("{:.9e}", n.as_f64().unwrap_or(f64::NAN)))
        }
        Value::Array(items) => Value::Array(items.into_iter().map(canonical).collect()),
        Value::Object(map) => {
            Value::Object(map.into_iter().map(|(k, v)| (k, canonical(v))).collect())
        }
        other => other,
    }
}

pub(crate) fn part_of(bytes: &[u8], file: &str) -> Part {
    Part {
        file: file.into(),
        bytes: bytes.len() as u64,
        sha256: hex::encode(Sha256::digest(bytes)),
    }
}

/// `path` itself if it holds a manifest, else `path/model` if that does.
pub fn resolve_dir(path: &Path) -> Result<PathBuf> {
    resolve_artifact_dir(path, MANIFEST_FILE, MODEL_DIR, "a DeepBRDF model")
}

/// `path` itself if it holds `manifest`, else `path/inner` if that does; else an error saying
/// that `path` is not `what` (an artifact of this crate: a model, a recovery network).
pub(crate) fn resolve_artifact_dir(
    path: &Path,
    manifest: &str,
    inner: &str,
    what: &str,
) -> Result<PathBuf> {
    if path.join(manifest).is_file() {
        return Ok(path.to_path_buf());
    }
    let inner_dir = path.join(inner);
    if inner_dir.join(manifest).is_file() {
        return Ok(inner_dir);
    }
    if !path.exists() {
        return Err(ModelError::io(path, std::io::Error::from(std::io::ErrorKind::NotFound)));
    }
    Err(ModelError::format(path, format!("not {what} (no {manifest} here or in {inner}/)")))
}

/// Writes an artifact directory `dir` with `write_parts` into a temporary sibling and renames
/// it into place. An existing `dir` is replaced only if it holds `manifest` (it is `what`).
pub(crate) fn save_dir(
    dir: &Path,
    manifest: &str,
    what: &str,
    write_parts: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if dir.exists() && !dir.join(manifest).is_file() {
        return Err(ModelError::Invalid(format!(
            "{} exists and is not {what}; not replacing it",
            dir.display()
        )));
    }
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.with_file_name(format!(".{name}.tmp{}", std::process::id()));
    if tmp.exists() {
        fs::remove_dir_all(&tmp).map_err(|e| ModelError::io(&tmp, e))?;
    }
    fs::create_dir_all(&tmp).map_err(|e| ModelError::io(&tmp, e))?;
    let result = write_parts(&tmp).and_then(|()| replace_dir(&tmp, dir));
    if result.is_err() {
        let _ = fs::remove_dir_all(&tmp);
    }
    result
}

/// Moves the finished directory `tmp` to `dir`, replacing an older artifact there.
fn replace_dir(tmp: &Path, dir: &Path) -> Result<()> {
    if dir.exists() {
        let old = tmp.with_extension("old");
        if old.exists() {
            fs::remove_dir_all(&old).map_err(|e| ModelError::io(&old, e))?;
        }
        fs::rename(dir, &old).map_err(|e| ModelError::io(dir, e))?;
        fs::rename(tmp, dir).map_err(|e| ModelError::io(dir, e))?;
        fs::remove_dir_all(&old).map_err(|e| ModelError::io(&old, e))?;
    } else {
        fs::rename(tmp, dir).map_err(|e| ModelError::io(dir, e))?;
    }
    sync_dir_of(dir);
    Ok(())
}

#[cfg(test)]
#[path = "artifact_fuzz.rs"]
mod fuzz;

#[cfg(test)]
#[path = "artifact_tests.rs"]
mod tests;

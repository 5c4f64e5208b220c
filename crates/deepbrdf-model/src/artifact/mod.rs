//! The one container every saved network shares: the autoencoder's model directory
//! ([`crate::autoencoder::artifact`]), the recovery CNN's directory ([`crate::recovery::artifact`])
//! and the regressor's single file ([`crate::regressor::artifact`]).
//!
//! Each saves a JSON manifest ([`Manifest`]: format, version, an id over its content) beside
//! its parts; a part is recorded by its size and SHA-256 ([`Part`]), so an edited manifest or
//! weights swapped in from another network are refused when loading, naming the file. The
//! pieces here are what all three share:
//! - [`files`]: crash-safe writes (temporary file, fsync, rename), size-limited reads, packed
//!   weights files, pretty-JSON manifests and their format check;
//! - [`sections`]: a checksummed file of named sections (the regressor, training checkpoints);
//! - [`dir`]: a directory of parts written beside its destination and renamed into place;
//! - here: the id ([`content_id`]), the parts' checksums, a network's weights as bytes and back.

pub(crate) mod dir;
pub(crate) mod files;
pub(crate) mod sections;

use std::ops::RangeInclusive;
use std::path::Path;

use burn::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::{ModelError, Result};

/// What a saved network's manifest declares: its format and version, and an id over the content
/// that identifies the network ([`Manifest::content`]).
pub(crate) trait Manifest: Serialize + DeserializeOwned {
    /// The format name written and read (`deepbrdf-model`, ...).
    const FORMAT: &'static str;
    /// The versions this build reads.
    const VERSIONS: RangeInclusive<u32>;
    /// What the network is, in words ("a DeepBRDF model").
    const WHAT: &'static str;

    /// The format and version the manifest declares.
    fn format(&self) -> (&str, u32);
    /// The id it carries.
    fn id(&self) -> &str;
    /// What the id is computed over.
    fn content(&self) -> serde_json::Value;

    /// The id its content has ([`content_id`]).
    fn computed_id(&self) -> String {
        content_id(self.content())
    }
}

/// Parses a manifest of kind `M` from `bytes` read from `path`, checking its format and version.
pub(crate) fn parse_manifest<M: Manifest>(path: &Path, bytes: &[u8]) -> Result<M> {
    let manifest: M = serde_json::from_slice(bytes)
        .map_err(|e| ModelError::format(path, format!("not {} manifest: {e}", M::WHAT)))?;
    files::check_format(path, manifest.format(), M::FORMAT, M::VERSIONS)?;
    Ok(manifest)
}

/// Errors unless the manifest read from `path` carries the id of its content: an edited or
/// damaged manifest is refused.
pub(crate) fn check_id(path: &Path, manifest: &impl Manifest) -> Result<()> {
    match manifest.computed_id() == manifest.id() {
        true => Ok(()),
        false => Err(ModelError::mismatch(
            path,
            "the manifest was edited or damaged (its id does not match its content)",
        )),
    }
}

/// The id of a saved network: the first 16 bytes, in hex, of the SHA-256 of `content` in
/// [`canonical`] form.
pub(crate) fn content_id(content: serde_json::Value) -> String {
    let digest = Sha256::digest(canonical(content).to_string().as_bytes());
    hex::encode(&digest[..16])
}

/// The SHA-256 of `bytes`, in hex.
pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

/// Checksum of one part file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Part {
    pub(crate) file: String,
    pub(crate) bytes: u64,
    pub(crate) sha256: String,
}

impl Part {
    /// The record of `bytes` saved as `file`.
    pub(crate) fn of(bytes: &[u8], file: &str) -> Self {
        Self { file: file.into(), bytes: bytes.len() as u64, sha256: sha256_hex(bytes) }
    }

    /// Errors unless `bytes`, read from `path`, are this part: they belong to `owner` (e.g.
    /// "model 3f2a...") only if file name, size and checksum agree.
    pub(crate) fn check(&self, path: &Path, bytes: &[u8], what: &str, owner: &str) -> Result<()> {
        let file = path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
        match Self::of(bytes, &file) == *self {
            true => Ok(()),
            false => Err(ModelError::mismatch(
                path,
                format!("{what} do not belong to {owner} (checksum differs)"),
            )),
        }
    }
}

/// A network's parameters as burnpack bytes, without Burn's random parameter ids: the same
/// network always has the same bytes, hence the same checksum and id.
pub(crate) fn network_bytes<M: Module>(network: M) -> Result<Vec<u8>> {
    let bad = |e: String| ModelError::Invalid(format!("cannot serialise the weights: {e}"));
    let bytes = network.into_record().into_bytes().map_err(|e| bad(e.to_string()))?.to_vec();
    crate::record::rewrite(bytes, false, |name| name).map_err(|e| bad(e.to_string()))
}

/// Loads burnpack `weights` into `network` (any network).
pub(crate) fn load_weights<M: Module>(network: M, weights: Vec<u8>) -> Result<M> {
    let bad = |e: String| ModelError::Invalid(format!("the weights do not fit the network: {e}"));
    let record = crate::record::float_record(weights).map_err(|e| bad(e.to_string()))?;
    network.try_load_record(record).map_err(|e| bad(e.to_string()))
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

#[cfg(test)]
mod tests {
    use std::fs;
    use std::path::Path;

    use crate::device::DeviceKind;
    use crate::recovery::RecoveryArtifact;
    use crate::regressor::{Regressor, TargetKind};
    use crate::shipped::{DEFAULT_MODEL_DIR, REGRESSOR_DIR};
    use crate::ModelArtifact;

    /// The bytes of every file in `dir`, by name.
    fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<_> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap())
            .map(|e| (e.file_name().to_string_lossy().into_owned(), fs::read(e.path()).unwrap()))
            .collect();
        out.sort();
        out
    }

    /// The shipped model, its recovery CNN and its regressor load with the ids their manifests
    /// carry, and saving them again writes the same bytes: the files this container writes are
    /// the files earlier versions wrote.
    #[test]
    fn the_shipped_networks_load_and_save_byte_for_byte() {
        let shipped = Path::new(DEFAULT_MODEL_DIR);
        let out = tempfile::tempdir().unwrap();
        let manifest_id = |path: &Path| {
            let json: serde_json::Value = serde_json::from_slice(&fs::read(path).unwrap()).unwrap();
            json["id"].as_str().unwrap().to_string()
        };

        let model = ModelArtifact::load(shipped).unwrap();
        assert_eq!(model.id(), manifest_id(&shipped.join("model/model.json")));
        model.save(&out.path().join("model")).unwrap();
        assert_eq!(files(&out.path().join("model")), files(&shipped.join("model")));

        let recovery = RecoveryArtifact::load(shipped).unwrap();
        assert_eq!(recovery.id(), manifest_id(&shipped.join("recovery/recovery.json")));
        recovery.save(&out.path().join("recovery")).unwrap();
        assert_eq!(files(&out.path().join("recovery")), files(&shipped.join("recovery")));

        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let file = shipped.join(REGRESSOR_DIR).join(TargetKind::DeepBrdf.file_name());
        let regressor =
            Regressor::load_for(&file, TargetKind::DeepBrdf, model.id(), 10, &device).unwrap();
        regressor.save(&out.path().join("r")).unwrap();
        assert_eq!(fs::read(out.path().join("r")).unwrap(), fs::read(&file).unwrap());
    }
}

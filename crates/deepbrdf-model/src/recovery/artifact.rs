//! The saved recovery CNN, in the container every saved network shares ([`crate::artifact`]):
//! a directory with a manifest whose id covers the configuration, what the network predicts,
//! its provenance and the checksum of its weights.
//!
//! ```text
//! recovery/
//!   recovery.json   id, network configuration, target (the DeepBRDF model id whose latent it
//!                   predicts, or the 7 attributes), standardisation, provenance, weights checksum
//!   weights.bpk     the network's parameters (burnpack), written packed as a model's are
//! ```
//!
//! A network for one DeepBRDF model is refused for another ([`RecoveryArtifact::check_model`]):
//! its outputs mean nothing in another model's latent space.

use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

use burn::prelude::*;
use burn::tensor::TensorData;
use serde::{Deserialize, Serialize};

use super::network::{RecoveryConfig, RecoveryNet};
use super::step::RecoveryTrained;
use crate::artifact::files::{read_limited, read_weights, write_manifest, write_weights};
use crate::artifact::Manifest as _;
use crate::artifact::{check_id, dir, load_weights, network_bytes, parse_manifest, Part};
use crate::error::{ModelError, Result};

/// File name of the manifest.
pub const RECOVERY_MANIFEST: &str = "recovery.json";
/// File name of the weights (the model's, [`crate::autoencoder::artifact::WEIGHTS_FILE`]).
pub const RECOVERY_WEIGHTS: &str = crate::autoencoder::artifact::WEIGHTS_FILE;
/// Name of the recovery network's directory beside a model (`models/default/recovery`).
pub const RECOVERY_DIR: &str = "recovery";

/// What the network's outputs are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RecoveryTarget {
    /// The k latent values of the DeepBRDF model with this id (decoded by that model).
    Latent { model_id: String, k: usize },
    /// The 7 Lambertian + GGX attributes of §5.1 (diffuse RGB, specular RGB, roughness): the
    /// analytic baseline of the same CNN.
    Attributes,
}

impl RecoveryTarget {
    /// Number of outputs.
    pub fn outputs(&self) -> usize {
        match self {
            Self::Latent { k, .. } => *k,
            Self::Attributes => 7,
        }
    }
}

/// How the network was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecoveryProvenance {
    /// The render set's folder as given, and its manifest's digest.
    pub set: String,
    pub set_digest: String,
    /// Training images and their materials.
    pub images: usize,
    pub materials: Vec<String>,
    /// Digest of the prepared examples.
    pub data_fingerprint: String,
    /// The loop's settings and the preset's name.
    pub train_config: serde_json::Value,
    pub epochs: usize,
    pub final_loss: f64,
    pub train_seconds: f64,
    pub device: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Manifest {
    format: String,
    version: u32,
    id: String,
    config: serde_json::Value,
    target: RecoveryTarget,
    mean: Vec<f32>,
    scale: Vec<f32>,
    provenance: RecoveryProvenance,
    weights: Part,
}

impl crate::artifact::Manifest for Manifest {
    const FORMAT: &'static str = "deepbrdf-recovery";
    const VERSIONS: RangeInclusive<u32> = 1..=1;
    const WHAT: &'static str = "a recovery network";

    fn format(&self) -> (&str, u32) {
        (&self.format, self.version)
    }

    fn id(&self) -> &str {
        &self.id
    }

    fn content(&self) -> serde_json::Value {
        serde_json::json!({
            "config": self.config,
            "target": self.target,
            "mean": self.mean,
            "scale": self.scale,
            "provenance": self.provenance,
            "weights": self.weights,
        })
    }
}

/// A trained recovery network in memory.
#[derive(Debug, Clone)]
pub struct RecoveryArtifact {
    config: RecoveryConfig,
    manifest: Manifest,
    weights: Vec<u8>,
}

impl RecoveryArtifact {
    /// Bundles a trained network with what it predicts.
    pub fn new(
        config: RecoveryConfig,
        target: RecoveryTarget,
        trained: &RecoveryTrained,
        provenance: RecoveryProvenance,
    ) -> Result<Self> {
        if target.outputs() != config.outputs {
            return Err(ModelError::Invalid(format!(
                "the network has {} outputs, its target {target:?} {}",
                config.outputs,
                target.outputs()
            )));
        }
        let weights = network_bytes(trained.model.clone())?;
        let mut manifest = Manifest {
            format: <Manifest as crate::artifact::Manifest>::FORMAT.into(),
            version: 1,
            id: String::new(),
            config: serde_json::to_value(&config)
                .map_err(|e| ModelError::Invalid(format!("cannot serialise: {e}")))?,
            target,
            mean: trained.mean.clone(),
            scale: trained.scale.clone(),
            provenance,
            weights: Part::of(&weights, RECOVERY_WEIGHTS),
        };
        manifest.id = manifest.computed_id();
        Ok(Self { config, manifest, weights })
    }

    pub fn id(&self) -> &str {
        &self.manifest.id
    }

    pub fn config(&self) -> &RecoveryConfig {
        &self.config
    }

    pub fn target(&self) -> &RecoveryTarget {
        &self.manifest.target
    }

    pub fn provenance(&self) -> &RecoveryProvenance {
        &self.manifest.provenance
    }

    /// Errors unless this network predicts the latent of the DeepBRDF model `model_id`.
    pub fn check_model(&self, model_id: &str) -> Result<()> {
        match &self.manifest.target {
            RecoveryTarget::Latent { model_id: own, .. } if own == model_id => Ok(()),
            RecoveryTarget::Latent { model_id: own, .. } => Err(ModelError::Invalid(format!(
                "this recovery network predicts the latent of DeepBRDF model {own}, not of model \
                 {model_id}: train one for this model with `experiments train-recovery`"
            ))),
            RecoveryTarget::Attributes => Err(ModelError::Invalid(
                "this recovery network predicts the 7 analytic attributes, not a DeepBRDF latent"
                    .into(),
            )),
        }
    }

    /// The network on `device` (inference) with its standardisation.
    pub fn predictor(&self, device: &Device) -> Result<Predictor> {
        let device = device.clone().without_autodiff();
        let net = crate::seeded::exclusive(|| self.config.init(&device))?;
        let net = load_weights(net, self.weights.clone())?.valid();
        Ok(Predictor {
            net,
            side: self.config.input_side,
            mean: self.manifest.mean.clone(),
            scale: self.manifest.scale.clone(),
            device,
        })
    }

    /// Writes the directory `dir` (beside it, then renamed into place); an existing `dir` is
    /// replaced only if it is itself a recovery network.
    pub fn save(&self, dir: &Path) -> Result<()> {
        dir::save(dir, RECOVERY_MANIFEST, "a recovery network", |tmp| {
            write_weights(&tmp.join(RECOVERY_WEIGHTS), &self.weights)?;
            write_manifest(&tmp.join(RECOVERY_MANIFEST), &self.manifest)
        })
    }

    /// Loads a recovery network directory (or the `recovery/` inside a model directory),
    /// checking its parts belong together.
    pub fn load(path: &Path) -> Result<Self> {
        let dir = resolve(path)?;
        let manifest_path = dir.join(RECOVERY_MANIFEST);
        let text = read_limited(&manifest_path, 16 << 20)?;
        let manifest: Manifest = parse_manifest(&manifest_path, &text)?;
        let config: RecoveryConfig =
            serde_json::from_value(manifest.config.clone()).map_err(|e| {
                ModelError::format(&manifest_path, format!("bad network configuration: {e}"))
            })?;
        config.validate()?;
        let k = config.outputs;
        if manifest.target.outputs() != k || manifest.mean.len() != k || manifest.scale.len() != k {
            return Err(ModelError::format(
                &manifest_path,
                format!("the network has {k} outputs; its target and standardisation disagree"),
            ));
        }
        let weights_path = dir.join(RECOVERY_WEIGHTS);
        let weights = read_weights(&weights_path, 1 << 30)?;
        let owner = format!("recovery network {}", manifest.id);
        manifest.weights.check(&weights_path, &weights, "these weights", &owner)?;
        check_id(&manifest_path, &manifest)?;
        Ok(Self { config, manifest, weights })
    }
}

/// `path` if it holds a recovery manifest, else `path/recovery` if that does.
fn resolve(path: &Path) -> Result<PathBuf> {
    dir::resolve(path, RECOVERY_MANIFEST, RECOVERY_DIR, "a recovery network")
}

/// A loaded recovery network: prepared images in, targets out.
#[derive(Debug)]
pub struct Predictor {
    net: RecoveryNet,
    side: usize,
    mean: Vec<f32>,
    scale: Vec<f32>,
    device: Device,
}

impl Predictor {
    /// Side of the images it takes.
    pub fn side(&self) -> usize {
        self.side
    }

    /// The targets of `images` (`n` prepared images `[3, side, side]`, concatenated), `n`
    /// rows of outputs.
    pub fn predict(&self, images: &[f32]) -> Result<Vec<Vec<f32>>> {
        let per = 3 * self.side * self.side;
        let n = images.len() / per;
        if n == 0 || n * per != images.len() {
            return Err(ModelError::Invalid(format!(
                "{} values are not whole {}x{} colour images",
                images.len(),
                self.side,
                self.side
            )));
        }
        let k = self.mean.len();
        let mut rows = Vec::with_capacity(n);
        for chunk in images.chunks(64 * per) {
            let b = chunk.len() / per;
            let x = Tensor::<4>::from_data(
                TensorData::new(chunk.to_vec(), [b, 3, self.side, self.side]),
                &self.device,
            );
            let y =
                crate::read_back::values(self.net.forward(x), "the recovery network's outputs")?;
            for row in y.chunks_exact(k) {
                rows.push(
                    row.iter().enumerate().map(|(j, v)| v * self.scale[j] + self.mean[j]).collect(),
                );
            }
        }
        Ok(rows)
    }
}

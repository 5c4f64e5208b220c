//! The saved regressor: one checksummed file ([`crate::container::Container`], written
//! atomically) holding a JSON manifest and the network's weights (burnpack). The manifest names
//! the representation the outputs belong to ([`Target`]: a DeepBRDF model's id, or an IPCA
//! basis's digest, and k), the network's shape, the normalisation of inputs and targets
//! ([`Scaling`]) and how it was trained; its id is a SHA-256 over all of that and the weights.
//! Loading it for another model is refused ([`Regressor::load_for`]).

use std::fmt;
use std::path::Path;

use burn::prelude::*;
use burn::tensor::TensorData;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::network::{NetworkShape, RegressorNet, ATTRIBUTES};
use super::scaling::{features, Scaling};
use crate::atomic::check_format;
use crate::container::Container;
use crate::error::{ModelError, Result};

/// The container kind tag of a regressor file.
pub const REGRESSOR_KIND: &[u8; 8] = b"REGRESS1";
const FORMAT: &str = "deepbrdf-regressor";
const VERSION: u32 = 1;

/// What the regressor's outputs are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetKind {
    /// The k latent values of a DeepBRDF model (eq. 2).
    DeepBrdf,
    /// The k coefficients of an IPCA basis (§4, Nielsen et al. 2015).
    Ipca,
}

impl TargetKind {
    /// The file name of this kind's regressor inside a regressor directory.
    pub fn file_name(self) -> &'static str {
        match self {
            Self::DeepBrdf => "deepbrdf.regressor",
            Self::Ipca => "ipca.regressor",
        }
    }
}

impl fmt::Display for TargetKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::DeepBrdf => "DeepBRDF model",
            Self::Ipca => "IPCA basis",
        })
    }
}

/// The representation a regressor predicts for.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Target {
    pub kind: TargetKind,
    /// The DeepBRDF model's id ([`crate::ModelArtifact::id`]) or the IPCA basis's digest.
    pub owner_id: String,
    /// Number of outputs.
    pub k: usize,
}

/// How a regressor was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegressorProvenance {
    pub data_label: String,
    pub materials: Vec<String>,
    pub data_fingerprint: String,
    /// The [`super::RegressorConfig`], as JSON.
    pub config: serde_json::Value,
    pub epochs: usize,
    /// The last epoch's mean loss (eq. 7's relative error, averaged over the epoch's batches).
    pub final_loss: f64,
    /// Mean relative error `||Y^ - Y|| / ||Y||` over the training pairs after training.
    pub train_relative_error: f64,
    pub train_seconds: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Manifest {
    format: String,
    version: u32,
    id: String,
    target: Target,
    shape: NetworkShape,
    scaling: Scaling,
    provenance: RegressorProvenance,
    weights_sha256: String,
}

impl Manifest {
    /// SHA-256 over everything but the id.
    fn digest(&self) -> String {
        let mut content = serde_json::to_value(self).unwrap_or_default();
        content["id"] = serde_json::Value::Null;
        let text = crate::artifact::canonical(content).to_string();
        hex::encode(&Sha256::digest(text.as_bytes())[..16])
    }
}

/// A trained regressor, ready to predict.
#[derive(Debug)]
pub struct Regressor {
    manifest: Manifest,
    weights: Vec<u8>,
    net: RegressorNet,
    device: Device,
}

impl Regressor {
    /// Bundles a trained network (for inference, not autodiff) with what it needs.
    pub(super) fn new(
        target: Target,
        shape: NetworkShape,
        scaling: Scaling,
        provenance: RegressorProvenance,
        net: RegressorNet,
        device: &Device,
    ) -> Result<Self> {
        scaling.validate(target.k)?;
        let bytes = net
            .clone()
            .into_record()
            .into_bytes()
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the weights: {e}")))?
            .to_vec();
        // Without Burn's random parameter ids: the same network has the same bytes.
        let weights = crate::record::rewrite(bytes, false, |name| name)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the weights: {e}")))?;
        let mut manifest = Manifest {
            format: FORMAT.into(),
            version: VERSION,
            id: String::new(),
            target,
            shape,
            scaling,
            provenance,
            weights_sha256: hex::encode(Sha256::digest(&weights)),
        };
        manifest.id = manifest.digest();
        Ok(Self { manifest, weights, net, device: device.clone().without_autodiff() })
    }

    pub(super) fn set_train_error(&mut self, error: f64) -> Result<()> {
        self.manifest.provenance.train_relative_error = error;
        self.manifest.id = self.manifest.digest();
        Ok(())
    }

    /// The regressor's id.
    pub fn id(&self) -> &str {
        &self.manifest.id
    }

    /// What it predicts for.
    pub fn target(&self) -> &Target {
        &self.manifest.target
    }

    /// How it was trained.
    pub fn provenance(&self) -> &RegressorProvenance {
        &self.manifest.provenance
    }

    /// The recorded normalisation.
    pub fn scaling(&self) -> &Scaling {
        &self.manifest.scaling
    }

    /// Eq. (7): the k values of a material with these 7 attributes (diffuse RGB, specular RGB,
    /// roughness; the roughness must be positive).
    pub fn predict(&self, attributes: &[f64; 7]) -> Result<Vec<f32>> {
        let x = self.manifest.scaling.standardise(&features(attributes)?);
        let x = Tensor::<2>::from_data(TensorData::new(x.to_vec(), [1, ATTRIBUTES]), &self.device);
        let out = crate::read_back::values(
            self.net.forward(x, self.manifest.shape.negative_slope),
            "the regressor's output",
        )?;
        let y = self.manifest.scaling.unstandardise(&out);
        if y.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::Invalid("the regressor's prediction is not finite".into()));
        }
        Ok(y)
    }

    /// Writes the regressor to `path` atomically; an existing file is replaced only if it is
    /// itself a regressor.
    pub fn save(&self, path: &Path) -> Result<()> {
        if path.exists() && Container::load(path, REGRESSOR_KIND).is_err() {
            return Err(ModelError::Invalid(format!(
                "{} exists and is not a regressor; not replacing it",
                path.display()
            )));
        }
        let json = serde_json::to_vec_pretty(&self.manifest)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the manifest: {e}")))?;
        let mut c = Container::new();
        c.push("manifest", json);
        c.push("weights", self.weights.clone());
        c.save(path, REGRESSOR_KIND)
    }

    /// Loads a regressor file, checking that its parts belong together.
    pub fn load(path: &Path, device: &Device) -> Result<Self> {
        let mut c = Container::load(path, REGRESSOR_KIND)?;
        let bad = |problem: String| ModelError::format(path, problem);
        let json = c.take("manifest").ok_or_else(|| bad("no manifest section".into()))?;
        let weights = c.take("weights").ok_or_else(|| bad("no weights section".into()))?;
        let manifest: Manifest = serde_json::from_slice(&json)
            .map_err(|e| bad(format!("not a regressor manifest: {e}")))?;
        check_format(path, (&manifest.format, manifest.version), FORMAT, VERSION..=VERSION)?;
        if manifest.digest() != manifest.id {
            return Err(ModelError::mismatch(
                path,
                "the manifest was edited or damaged (its id does not match its content)",
            ));
        }
        if hex::encode(Sha256::digest(&weights)) != manifest.weights_sha256 {
            return Err(ModelError::mismatch(path, "the weights do not belong to the manifest"));
        }
        let shape = manifest.shape;
        if shape.outputs != manifest.target.k || shape.hidden == 0 || shape.hidden > 1 << 16 {
            return Err(bad(format!("a network of shape {shape:?} for k = {}", manifest.target.k)));
        }
        manifest.scaling.validate(manifest.target.k).map_err(|e| bad(e.to_string()))?;
        let device = device.clone().without_autodiff();
        let skeleton = crate::seeded::exclusive(|| RegressorNet::init(&shape, &device));
        let record = crate::record::float_record(weights.clone())
            .map_err(|e| bad(format!("bad weights: {e}")))?;
        let net = skeleton
            .try_load_record(record)
            .map_err(|e| bad(format!("the weights do not fit the network: {e}")))?;
        Ok(Self { manifest, weights, net, device })
    }

    /// Loads the regressor of `kind` in `dir` (or the file `dir` itself) and checks that it
    /// was trained for the representation `owner_id` with `k` values: a regressor of another
    /// model is refused, naming both.
    pub fn load_for(
        dir: &Path,
        kind: TargetKind,
        owner_id: &str,
        k: usize,
        device: &Device,
    ) -> Result<Self> {
        let path = if dir.is_dir() { dir.join(kind.file_name()) } else { dir.to_path_buf() };
        if !path.exists() {
            return Err(ModelError::Invalid(format!(
                "no regressor at {} (train one with `experiments train-regressor`)",
                path.display()
            )));
        }
        let regressor = Self::load(&path, device)?;
        let t = regressor.target();
        if t.kind != kind || t.owner_id != owner_id || t.k != k {
            return Err(ModelError::mismatch(
                &path,
                format!(
                    "this regressor belongs to {} {} (k = {}), not to {kind} {owner_id} (k = {k}); \
                     train one for it with `experiments train-regressor`",
                    t.kind, t.owner_id, t.k
                ),
            ));
        }
        Ok(regressor)
    }
}

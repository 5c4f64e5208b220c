//! The saved regressor, in the container every saved network shares ([`crate::artifact`]): one
//! checksummed file of sections ([`crate::artifact::sections::Container`], written atomically)
//! holding a JSON manifest and the network's weights (burnpack). The manifest names
//! the representation the outputs belong to ([`Target`]: a DeepBRDF model's id, or an IPCA
//! basis's digest, and k), the network's shape, the normalisation of inputs and targets
//! ([`Scaling`]) and how it was trained; its id is a SHA-256 over all of that and the weights.
//! Loading it for another model is refused ([`Regressor::load_for`]).

use std::fmt;
use std::ops::RangeInclusive;
use std::path::Path;

use burn::prelude::*;
use burn::tensor::TensorData;
use serde::{Deserialize, Serialize};

use super::network::{NetworkShape, RegressorNet, ATTRIBUTES};
use super::scaling::{features, Scaling};
use crate::artifact::sections::Container;
use crate::artifact::Manifest as _;
use crate::artifact::{check_id, load_weights, network_bytes, parse_manifest, sha256_hex};
use crate::error::{ModelError, Result};

/// The container kind tag of a regressor file.
pub const REGRESSOR_KIND: &[u8; 8] = b"REGRESS1";

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

impl crate::artifact::Manifest for Manifest {
    const FORMAT: &'static str = "deepbrdf-regressor";
    const VERSIONS: RangeInclusive<u32> = 1..=1;
    const WHAT: &'static str = "a regressor";

    fn format(&self) -> (&str, u32) {
        (&self.format, self.version)
    }

    fn id(&self) -> &str {
        &self.id
    }

    /// Everything but the id (the id's own field set to null).
    fn content(&self) -> serde_json::Value {
        let mut content = serde_json::to_value(self).unwrap_or_default();
        content["id"] = serde_json::Value::Null;
        content
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
        let weights = network_bytes(net.clone())?;
        let mut manifest = Manifest {
            format: <Manifest as crate::artifact::Manifest>::FORMAT.into(),
            version: 1,
            id: String::new(),
            target,
            shape,
            scaling,
            provenance,
            weights_sha256: sha256_hex(&weights),
        };
        manifest.id = manifest.computed_id();
        Ok(Self { manifest, weights, net, device: device.clone().without_autodiff() })
    }

    pub(super) fn set_train_error(&mut self, error: f64) -> Result<()> {
        self.manifest.provenance.train_relative_error = error;
        self.manifest.id = self.manifest.computed_id();
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
        let manifest: Manifest = parse_manifest(path, &json)?;
        check_id(path, &manifest)?;
        if sha256_hex(&weights) != manifest.weights_sha256 {
            return Err(ModelError::mismatch(path, "the weights do not belong to the manifest"));
        }
        let shape = manifest.shape;
        if shape.outputs != manifest.target.k || shape.hidden == 0 || shape.hidden > 1 << 16 {
            return Err(bad(format!("a network of shape {shape:?} for k = {}", manifest.target.k)));
        }
        manifest.scaling.validate(manifest.target.k).map_err(|e| bad(e.to_string()))?;
        let device = device.clone().without_autodiff();
        let skeleton = crate::seeded::exclusive(|| RegressorNet::init(&shape, &device));
        let net = load_weights(skeleton, weights.clone()).map_err(|e| bad(e.to_string()))?;
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

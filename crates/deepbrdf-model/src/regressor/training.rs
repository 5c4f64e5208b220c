//! Training the regressor of eq. (7) through the shared loop ([`crate::train::run`]): its
//! [`TrainStep`] (the network, and the loss of a batch: the mean over its examples of
//! `||Y^ - Y|| / ||Y||`, eq. (7)'s relative error, on the targets themselves) and its settings.

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::artifact::{Regressor, RegressorProvenance, Target};
use super::network::{NetworkShape, RegressorNet, ATTRIBUTES};
use super::scaling::{features, Scaling};
use crate::error::{ModelError, Result};
use crate::train::{adam, on_device, run, LoopConfig, Session, TrainStep};

/// Added under the square roots of the loss (a zero residual has a finite gradient).
const TINY: f64 = 1e-12;

/// How a regressor is built and trained.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RegressorConfig {
    /// Hidden units (Fig. 11: 100).
    pub hidden: usize,
    /// Leaky ReLU slope.
    pub negative_slope: f64,
    /// The loop's settings (Adam, schedule, epochs, batches, seed).
    pub training: LoopConfig,
}

impl Default for RegressorConfig {
    /// Fig. 11's network; Adam at 1e-3 falling to 5% along a cosine, 3000 epochs of batches
    /// of 8 (100 training materials: ~40,000 steps of a 1,800-parameter network, ~20 s on 2
    /// cores), seed 0.
    fn default() -> Self {
        Self {
            hidden: 100,
            negative_slope: 0.01,
            training: LoopConfig::new(adam())
                .with_learning_rate(1e-3)
                .with_final_lr_factor(0.05)
                .with_epochs(3000)
                .with_batch_size(8)
                .with_checkpoint_seconds(30.0),
        }
    }
}

/// Training pairs: each material's 7 attributes and its k targets (latent values or IPCA
/// coefficients).
#[derive(Debug, Clone)]
pub struct RegressorData {
    /// Where the materials come from (e.g. "merl").
    pub label: String,
    pub names: Vec<String>,
    /// Diffuse RGB, specular RGB, roughness (`deepbrdf_eval::attributes::Attributes::to_array`).
    pub attributes: Vec<[f64; 7]>,
    pub targets: Vec<Vec<f32>>,
}

impl RegressorData {
    /// A digest of the pairs (a checkpoint resumes only on the same data).
    pub fn fingerprint(&self) -> String {
        let mut h = Sha256::new();
        for ((name, a), t) in self.names.iter().zip(&self.attributes).zip(&self.targets) {
            h.update(name.as_bytes());
            h.update([0]);
            a.iter().for_each(|v| h.update(v.to_le_bytes()));
            t.iter().for_each(|v| h.update(v.to_le_bytes()));
        }
        hex::encode(&h.finalize()[..16])
    }
}

/// The step: standardised inputs, raw targets, the target scaling as tensors.
struct Step {
    inputs: Vec<[f32; ATTRIBUTES]>,
    targets: Vec<Vec<f32>>,
    scaling: Scaling,
    shape: NetworkShape,
    seed: u64,
}

impl Step {
    fn rows(&self, indices: &[usize], device: &Device) -> (Tensor<2>, Tensor<2>) {
        let k = self.shape.outputs;
        let x: Vec<f32> = indices.iter().flat_map(|&i| self.inputs[i]).collect();
        let y: Vec<f32> = indices.iter().flat_map(|&i| self.targets[i].iter().copied()).collect();
        let n = indices.len();
        (
            Tensor::from_data(TensorData::new(x, [n, ATTRIBUTES]), device),
            Tensor::from_data(TensorData::new(y, [n, k]), device),
        )
    }
}

/// The per-example relative errors `||Y^ - Y|| / ||Y||` (`[batch]`) of standardised outputs.
pub(super) fn relative_errors(
    outputs: Tensor<2>,
    targets: Tensor<2>,
    scaling: &Scaling,
    device: &Device,
) -> Tensor<1> {
    let k = scaling.k();
    let row = |v: &[f64]| {
        let v: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        Tensor::<2>::from_data(TensorData::new(v, [1, k]), device)
    };
    let predicted = outputs * row(&scaling.target_std) + row(&scaling.target_mean);
    let diff = predicted - targets.clone();
    let num = (diff.clone() * diff).sum_dim(1).add_scalar(TINY).sqrt();
    let den = (targets.clone() * targets).sum_dim(1).add_scalar(TINY).sqrt();
    (num / den).squeeze_dim(1)
}

impl TrainStep for Step {
    type Model = RegressorNet;

    fn init(&mut self, device: &Device) -> Result<RegressorNet> {
        Ok(crate::seeded::with_seed(self.seed, device, || RegressorNet::init(&self.shape, device)))
    }

    fn skeleton(&mut self, device: &Device) -> Result<RegressorNet> {
        Ok(crate::seeded::exclusive(|| RegressorNet::init(&self.shape, device)))
    }

    fn step(
        &mut self,
        model: &RegressorNet,
        _epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> Result<(f32, MultiGradientsParams)> {
        let (x, y) = self.rows(indices, device);
        let outputs = model.forward(x, self.shape.negative_slope);
        let loss = relative_errors(outputs, y, &self.scaling, device).mean(); // [1]
        let value: f32 = loss.clone().into_scalar();
        Ok((value, on_device(GradientsParams::from_grads(loss.backward(), model), device)))
    }
}

/// Trains a regressor on `data` for `target` (the representation its outputs belong to), in
/// `session`'s directory (checkpoints, log; resumable), and returns it ready to predict.
pub fn train_regressor(
    data: &RegressorData,
    config: &RegressorConfig,
    target: Target,
    session: &Session<'_>,
    device: &Device,
) -> Result<Regressor> {
    let n = data.attributes.len();
    if n < 2 || data.targets.len() != n || data.names.len() != n {
        return Err(ModelError::Invalid(format!(
            "a regressor needs at least 2 materials with attributes and targets; got {} names, \
             {n} attribute rows and {} targets",
            data.names.len(),
            data.targets.len()
        )));
    }
    if data.targets.iter().any(|t| t.len() != target.k) {
        return Err(ModelError::Invalid(format!(
            "the targets must have k = {} values each (the {})",
            target.k, target.kind
        )));
    }
    if config.hidden == 0 || !config.negative_slope.is_finite() {
        return Err(ModelError::Invalid(
            "the regressor needs hidden units and a finite slope".into(),
        ));
    }
    let feats = data.attributes.iter().map(features).collect::<Result<Vec<_>>>()?;
    let scaling = Scaling::fit(&feats, &data.targets)?;
    let shape = NetworkShape {
        hidden: config.hidden,
        outputs: target.k,
        negative_slope: config.negative_slope,
    };
    let mut step = Step {
        inputs: feats.iter().map(|f| scaling.standardise(f)).collect(),
        targets: data.targets.clone(),
        scaling: scaling.clone(),
        shape,
        seed: config.training.seed,
    };
    let identity = serde_json::json!({
        "network": "attribute regressor (eq. 7)",
        "config": config,
        "target": target,
    });
    let fingerprint = data.fingerprint();
    let outcome = run(&config.training, &identity, &fingerprint, n, &mut step, session, device)?;
    let provenance = RegressorProvenance {
        data_label: data.label.clone(),
        materials: data.names.clone(),
        data_fingerprint: fingerprint,
        config: serde_json::to_value(config)
            .map_err(|e| ModelError::Invalid(format!("cannot serialise the configuration: {e}")))?,
        epochs: outcome.log.len(),
        final_loss: outcome.log.last().map(|r| r.loss).unwrap_or(f64::NAN),
        train_relative_error: 0.0,
        train_seconds: outcome.seconds,
    };
    let mut regressor =
        Regressor::new(target, shape, scaling, provenance, outcome.model.valid(), device)?;
    let errors: Vec<f64> = data
        .attributes
        .iter()
        .zip(&data.targets)
        .map(|(a, t)| regressor.predict(a).map(|p| relative_error(&p, t)))
        .collect::<Result<_>>()?;
    regressor.set_train_error(errors.iter().sum::<f64>() / n as f64)?;
    Ok(regressor)
}

/// `||predicted - target|| / ||target||`.
pub fn relative_error(predicted: &[f32], target: &[f32]) -> f64 {
    let sq = |it: &mut dyn Iterator<Item = f64>| it.map(|v| v * v).sum::<f64>().sqrt();
    let num = sq(&mut predicted.iter().zip(target).map(|(p, t)| f64::from(p - t)));
    let den = sq(&mut target.iter().map(|&t| f64::from(t)));
    num / den.max(1e-30)
}

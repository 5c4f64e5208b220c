//! Training the recovery CNN (§5.2: "L_1 loss is used as the loss function") through the shared
//! loop ([`crate::train::run`]): the examples are in memory (images already prepared by
//! `deepbrdf_render::photo`), the targets standardised per output (the network predicts
//! `(target - mean) / scale`; the loss is the L1 distance of the unstandardised prediction to
//! the target, i.e. on the latent itself). Each epoch mirrors a seeded half of the images left
//! to right: a mirrored scene of an isotropic material on a symmetric shape under a mirrored
//! sky, the same material.

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::Progress;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sha2::{Digest, Sha256};

use super::network::{RecoveryConfig, RecoveryNet};
use crate::error::{ModelError, Result};
use crate::train::{on_device, run, EpochRecord, LoopConfig, Session, TrainStep};

/// Training examples: `n` images `[3, side, side]` (channel-major, concatenated) and their
/// targets (`outputs` values each).
#[derive(Debug, Clone)]
pub struct RecoveryData {
    pub side: usize,
    pub outputs: usize,
    pub images: Vec<f32>,
    pub targets: Vec<f32>,
}

impl RecoveryData {
    /// Number of examples (checked against the sizes).
    pub fn len(&self) -> Result<usize> {
        let per_image = 3 * self.side * self.side;
        if self.outputs == 0 || per_image == 0 {
            return Err(ModelError::Invalid("recovery data with no outputs or no pixels".into()));
        }
        let n = self.images.len() / per_image;
        if n * per_image != self.images.len() || n * self.outputs != self.targets.len() || n == 0 {
            return Err(ModelError::Invalid(format!(
                "{} image values and {} targets are not whole {}x{} images with {} targets each",
                self.images.len(),
                self.targets.len(),
                self.side,
                self.side,
                self.outputs
            )));
        }
        if self.targets.iter().chain(&self.images).any(|v| !v.is_finite()) {
            return Err(ModelError::Invalid("recovery data with a non-finite value".into()));
        }
        Ok(n)
    }

    /// Per-output mean and scale (standard deviation, at least 1e-3) of the targets.
    pub fn standardisation(&self) -> Result<(Vec<f32>, Vec<f32>)> {
        let n = self.len()?;
        let k = self.outputs;
        let mut mean = vec![0f64; k];
        let mut sq = vec![0f64; k];
        for row in self.targets.chunks_exact(k) {
            for j in 0..k {
                mean[j] += f64::from(row[j]);
                sq[j] += f64::from(row[j]).powi(2);
            }
        }
        let mean: Vec<f64> = mean.iter().map(|m| m / n as f64).collect();
        let scale = sq
            .iter()
            .zip(&mean)
            .map(|(s, m)| ((s / n as f64 - m * m).max(0.0)).sqrt().max(1e-3) as f32);
        Ok((mean.iter().map(|&m| m as f32).collect(), scale.collect()))
    }

    /// A digest of the examples (the loop's resume check).
    pub fn fingerprint(&self) -> String {
        let mut h = Sha256::new();
        h.update((self.side as u64).to_le_bytes());
        h.update((self.outputs as u64).to_le_bytes());
        for v in self.images.iter().chain(&self.targets) {
            h.update(v.to_le_bytes());
        }
        hex::encode(&h.finalize()[..16])
    }
}

/// The recovery CNN's [`TrainStep`].
struct RecoveryStep<'a> {
    config: &'a RecoveryConfig,
    data: &'a RecoveryData,
    mean: Vec<f32>,
    scale: Vec<f32>,
    seed: u64,
}

impl RecoveryStep<'_> {
    /// The batch of `indices` (mirrored per the epoch's draw) as tensors.
    fn batch(&self, epoch: usize, indices: &[usize], device: &Device) -> (Tensor<4>, Tensor<2>) {
        let (s, k) = (self.data.side, self.data.outputs);
        let per = 3 * s * s;
        let mut images = Vec::with_capacity(indices.len() * per);
        let mut targets = Vec::with_capacity(indices.len() * k);
        for &i in indices {
            let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ 0x6d69_7272_6f72);
            rng.set_stream((epoch as u64) << 32 | i as u64);
            let image = &self.data.images[i * per..(i + 1) * per];
            if rng.random::<bool>() {
                for row in image.chunks_exact(s) {
                    images.extend(row.iter().rev());
                }
            } else {
                images.extend_from_slice(image);
            }
            for (j, &t) in self.data.targets[i * k..(i + 1) * k].iter().enumerate() {
                targets.push((t - self.mean[j]) / self.scale[j]);
            }
        }
        let b = indices.len();
        let x = Tensor::<4>::from_data(TensorData::new(images, [b, 3, s, s]), device);
        let y = Tensor::<2>::from_data(TensorData::new(targets, [b, k]), device);
        (x, y)
    }
}

impl TrainStep for RecoveryStep<'_> {
    type Model = RecoveryNet;

    fn init(&mut self, device: &Device) -> Result<RecoveryNet> {
        crate::seeded::try_with_seed(self.seed, device, || self.config.init(device))
    }

    fn skeleton(&mut self, device: &Device) -> Result<RecoveryNet> {
        crate::seeded::exclusive(|| self.config.init(device))
    }

    fn step(
        &mut self,
        model: &RecoveryNet,
        epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> Result<(f32, MultiGradientsParams)> {
        let (x, y) = self.batch(epoch, indices, device);
        let k = self.data.outputs;
        let scale = Tensor::<1>::from_data(TensorData::new(self.scale.clone(), [k]), device)
            .reshape([1, k]);
        // L1 on the targets themselves: |scale * (pred - y)|, averaged.
        let loss = ((model.forward(x) - y) * scale).abs().mean(); // [1]
        let value: f32 = loss.clone().into_scalar();
        Ok((value, on_device(GradientsParams::from_grads(loss.backward(), model), device)))
    }
}

/// A trained recovery CNN.
#[derive(Debug)]
pub struct RecoveryTrained {
    pub model: RecoveryNet,
    pub mean: Vec<f32>,
    pub scale: Vec<f32>,
    pub log: Vec<EpochRecord>,
    pub seconds: f64,
    pub fingerprint: String,
}

/// Trains `config`'s CNN on `data` with `settings`, in `session`'s directory (resumable:
/// checkpoint, log and configuration as for every network of the loop).
pub fn train_recovery(
    config: &RecoveryConfig,
    settings: &LoopConfig,
    data: &RecoveryData,
    session: &Session<'_>,
    device: &Device,
    _progress: &dyn Progress,
) -> Result<RecoveryTrained> {
    config.validate()?;
    let n = data.len()?;
    if data.side != config.input_side || data.outputs != config.outputs {
        return Err(ModelError::Invalid(format!(
            "the data are {0}x{0} images with {1} targets; the network takes {2}x{2} and gives {3}",
            data.side, data.outputs, config.input_side, config.outputs
        )));
    }
    let (mean, scale) = data.standardisation()?;
    let identity = serde_json::json!({
        "network": "recovery-cnn",
        "config": serde_json::to_value(config).map_err(|e| ModelError::Invalid(e.to_string()))?,
        "loop": serde_json::to_value(settings).map_err(|e| ModelError::Invalid(e.to_string()))?,
    });
    let fingerprint = data.fingerprint();
    let mut step = RecoveryStep { config, data, mean, scale, seed: settings.seed };
    let outcome = run(settings, &identity, &fingerprint, n, &mut step, session, device)?;
    Ok(RecoveryTrained {
        model: outcome.model.valid(),
        mean: step.mean,
        scale: step.scale,
        log: outcome.log,
        seconds: outcome.seconds,
        fingerprint,
    })
}

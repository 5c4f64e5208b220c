//! Training of the autoencoder (§3.2): Adam on the masked L2 loss of eq. (4), seeded shuffling,
//! a per-epoch CSV log, NaN detection, and crash-safe checkpoints that a later call resumes
//! exactly (model, optimizer state, position in the epoch and the log).
//!
//! Determinism: the order of epoch `e` is a permutation drawn from `ChaCha8Rng(seed)` on stream
//! `e`, so it depends on nothing but the seed and the epoch; a resumed run therefore replays
//! the same batches, and with a deterministic backend (flex, ndarray on one thread) reaches the
//! same weights as an uninterrupted one.

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use burn::optim::{AdamConfig, GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::store::ModuleRecord;
use burn::tensor::{Bytes, TensorData};
use deepbrdf_data::augment::{fill_missing_layout, kept_slices, SliceSelection};
use deepbrdf_data::Progress;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::atomic::write_atomic;
use crate::autoencoder::{
    Autoencoder, AutoencoderConfig, INPUT_CHANNELS, INPUT_SIDE, INPUT_VALUES,
};
use crate::container::Container;
use crate::error::ModelError;
use crate::loss::masked_mse_centred;
use crate::training_set::TrainingSet;

/// File name of the checkpoint inside a training directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// File name of the per-epoch CSV log inside a training directory.
pub const LOG_FILE: &str = "train_log.csv";
/// File name of the training configuration (JSON) inside a training directory.
pub const CONFIG_FILE: &str = "train_config.json";
const CHECKPOINT_KIND: &[u8; 8] = b"CKPT0001";

/// Everything that determines a training run. Saved as JSON beside the checkpoint.
#[derive(Config, Debug)]
pub struct TrainConfig {
    /// The network.
    pub model: AutoencoderConfig,
    /// Adam's settings (§3.2: Adam [KB14]).
    pub optimizer: AdamConfig,
    /// Initial learning rate (§3.2: 2e-5).
    #[config(default = 2e-5)]
    pub learning_rate: f64,
    /// The learning rate falls along a half cosine to `learning_rate * final_lr_factor` at the
    /// last step; 1.0 keeps it constant (the paper's setting).
    #[config(default = 1.0)]
    pub final_lr_factor: f64,
    /// Passes over the training set (§3.2: 1000).
    #[config(default = 1000)]
    pub epochs: usize,
    /// BRDFs per mini-batch (§3.2: 32).
    #[config(default = 32)]
    pub batch_size: usize,
    /// Seed of the weight initialisation and of the shuffling.
    #[config(default = 0)]
    pub seed: u64,
    /// A checkpoint is written at the end of every epoch and, within an epoch, after a batch
    /// once this many seconds have passed since the last one.
    #[config(default = 60.0)]
    pub checkpoint_seconds: f64,
    /// Each batch is split into this many shards computed in parallel on CPU backends (1 on a
    /// GPU). Results depend on it (summation order), so it is part of the configuration.
    #[config(default = 1)]
    pub threads: usize,
    /// Slice-dropout augmentation (§3.2, Fig. 2); none in the paper's training.
    #[config(default = "None")]
    pub slice_dropout: Option<SliceDropoutConfig>,
}

/// Slice-dropout augmentation: some training inputs lose phi_d slices, each missing slice
/// filled from its nearest kept one (§3.2, `deepbrdf_data::augment`), while the target stays
/// the full BRDF, so the network learns the Fig. 2 task of completing sparse inputs.
#[derive(Config, Debug, PartialEq)]
pub struct SliceDropoutConfig {
    /// Probability that a training input is shown with missing slices.
    #[config(default = 0.5)]
    pub probability: f64,
    /// The selections drawn from, uniformly (`every:N` or `random:K`, as
    /// `deepbrdf_data::augment::SliceSelection` parses them); Fig. 2 uses 1/3 and 1/9.
    #[config(default = "vec![\"every:3\".to_string(), \"every:9\".to_string()]")]
    pub selections: Vec<String>,
}

impl SliceDropoutConfig {
    /// The parsed selections, or an error naming the bad one.
    pub fn parsed(&self) -> crate::error::Result<Vec<SliceSelection>> {
        if !(0.0..=1.0).contains(&self.probability) {
            return Err(ModelError::Invalid(format!(
                "slice-dropout probability {} is not in [0, 1]",
                self.probability
            )));
        }
        if self.selections.is_empty() {
            return Err(ModelError::Invalid("slice dropout needs at least one selection".into()));
        }
        self.selections.iter().map(|s| Ok(s.parse::<SliceSelection>()?)).collect()
    }
}

/// Adam as PyTorch (the paper's framework) defines it: epsilon 1e-8. Burn's default, 1e-5, is
/// larger than most of this network's gradients (eq. (4) divides by the ~3.3 million valid values
/// of each BRDF), which turns Adam into plain, tiny gradient steps: the loss then stays at the
/// variance of the data.
pub fn adam() -> AdamConfig {
    AdamConfig::new().with_epsilon(1e-8)
}

impl TrainConfig {
    /// §3.2's settings: Table 1, Adam with lr 2e-5, batches of 32, 1000 epochs.
    pub fn paper(k: usize) -> Self {
        Self::new(AutoencoderConfig::paper(k), adam())
    }

    /// The CPU preset: the spectral network of [`AutoencoderConfig::cpu`], Adam 1e-3 with
    /// cosine decay to 5e-5, batches of 8, 1000 epochs as the paper, slice dropout (half the
    /// inputs shown with 1/3 or 1/9 of the slices, §3.2) (about 15 s for 100 BRDFs on two
    /// cores, plus ~20 s for the basis fit and the projection of the filled inputs).
    pub fn cpu(k: usize) -> Self {
        Self::new(AutoencoderConfig::cpu(k), adam())
            .with_learning_rate(1e-3)
            .with_final_lr_factor(0.05)
            .with_epochs(1000)
            .with_batch_size(8)
            .with_threads(1)
            .with_slice_dropout(Some(SliceDropoutConfig::new()))
    }

    /// Checks the settings once.
    pub fn validate(&self) -> crate::error::Result<()> {
        self.model.validate()?;
        let lr_ok = self.learning_rate.is_finite() && self.learning_rate > 0.0;
        if !lr_ok || !(self.final_lr_factor > 0.0 && self.final_lr_factor <= 1.0) {
            return Err(ModelError::Invalid(format!(
                "learning rate {} with final factor {} (need lr > 0 and 0 < factor <= 1)",
                self.learning_rate, self.final_lr_factor
            )));
        }
        if self.threads == 0 || self.threads > 64 {
            return Err(ModelError::Invalid(format!("{} threads (1 to 64)", self.threads)));
        }
        if self.epochs == 0 || self.batch_size == 0 || self.batch_size > 4096 {
            return Err(ModelError::Invalid(format!(
                "{} epochs of batches of {} (both must be positive, batches at most 4096)",
                self.epochs, self.batch_size
            )));
        }
        if !(self.checkpoint_seconds >= 0.0) {
            return Err(ModelError::Invalid("checkpoint interval must be >= 0 seconds".into()));
        }
        if let Some(dropout) = &self.slice_dropout {
            dropout.parsed()?;
        }
        Ok(())
    }

    /// The learning rate of step `step` of `total` (half-cosine decay).
    pub fn learning_rate_at(&self, step: usize, total: usize) -> f64 {
        let end = self.learning_rate * self.final_lr_factor;
        let t = if total <= 1 { 0.0 } else { step as f64 / (total - 1) as f64 };
        end + 0.5 * (self.learning_rate - end) * (1.0 + (std::f64::consts::PI * t).cos())
    }
}

/// One row of the training log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// Epoch number, from 1.
    pub epoch: usize,
    /// Mean over the epoch's batches (weighted by batch size) of the eq. (4) loss.
    pub loss: f64,
    /// Learning rate of the epoch's last step.
    pub learning_rate: f64,
    /// Seconds the epoch took (summed over resumed pieces).
    pub seconds: f64,
}

/// The resumable state of a run besides the weights and the optimizer.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct TrainState {
    config: serde_json::Value,
    data_fingerprint: String,
    /// Completed epochs.
    epoch: usize,
    /// Next batch of the current epoch.
    batch: usize,
    loss_sum: f64,
    samples: usize,
    epoch_seconds: f64,
    total_seconds: f64,
    log: Vec<EpochRecord>,
}

/// A trained network and how it was trained.
#[derive(Debug)]
pub struct Trained {
    /// The network, on the caller's (non-autodiff) device.
    pub model: Autoencoder,
    /// The run's configuration.
    pub config: TrainConfig,
    /// The per-epoch log.
    pub log: Vec<EpochRecord>,
    /// Seconds spent training (over all resumed pieces).
    pub seconds: f64,
    /// Fingerprint of the training data.
    pub data_fingerprint: String,
    /// Final mapped-space MSE over valid values of each training BRDF, in set order.
    pub per_material_mse: Vec<f64>,
}

impl Trained {
    /// Mean over the training BRDFs of the mapped-space MSE.
    pub fn mean_mse(&self) -> f64 {
        self.per_material_mse.iter().sum::<f64>() / self.per_material_mse.len().max(1) as f64
    }

    /// The last epoch's training loss.
    pub fn final_loss(&self) -> f64 {
        self.log.last().map_or(f64::NAN, |r| r.loss)
    }
}

/// Trains the autoencoder of `config` on `data`, keeping its checkpoint, configuration and log
/// in `out_dir`.
///
/// With `resume`, a checkpoint in `out_dir` is continued exactly where it stopped (it must
/// have been written with the same configuration and data); without a checkpoint the run
/// starts afresh. Without `resume`, an existing checkpoint is an error: nothing is overwritten.
/// A run whose checkpoint has all its epochs only evaluates and returns the network.
pub fn train(
    config: &TrainConfig,
    data: &TrainingSet,
    out_dir: &Path,
    resume: bool,
    progress: &dyn Progress,
    device: &Device,
) -> crate::error::Result<Trained> {
    run(config, data, out_dir, resume, progress, device, None)
}

/// [`train`], optionally abandoned (as if killed) right after the batch `(epoch, batch)`
/// (0-based) has been applied and before anything is written for it.
fn run(
    config: &TrainConfig,
    data: &TrainingSet,
    out_dir: &Path,
    resume: bool,
    progress: &dyn Progress,
    device: &Device,
    kill_after: Option<(usize, usize)>,
) -> crate::error::Result<Trained> {
    config.validate()?;
    fs::create_dir_all(out_dir).map_err(|e| ModelError::io(out_dir, e))?;
    let checkpoint = out_dir.join(CHECKPOINT_FILE);
    let config_json = serde_json::to_value(config)
        .map_err(|e| ModelError::Invalid(format!("cannot serialise the configuration: {e}")))?;
    let fingerprint = data.fingerprint();
    let autodiff = device.clone().autodiff();

    let (mut model, mut optim, mut state) = if checkpoint.exists() {
        if !resume {
            return Err(ModelError::Invalid(format!(
                "{} already holds a training run ({CHECKPOINT_FILE}); resume it or choose \
                 another output directory",
                out_dir.display()
            )));
        }
        load_checkpoint(&checkpoint, config, &config_json, &fingerprint, &autodiff)?
    } else {
        let mut model = config.model.init_seeded(config.seed, &autodiff)?;
        if config.model.mean_offset {
            model = model.with_offset(&data.mean())?;
        }
        let state = TrainState {
            config: config_json.clone(),
            data_fingerprint: fingerprint.clone(),
            epoch: 0,
            batch: 0,
            loss_sum: 0.0,
            samples: 0,
            epoch_seconds: 0.0,
            total_seconds: 0.0,
            log: Vec::new(),
        };
        (model, config.optimizer.init(), state)
    };
    // The fixed offset, for centring batches on the CPU (see `Batch`).
    let offset = model.offset();
    // The spectral path's basis, fitted to the training set (again on resume: the fit is
    // deterministic), and the training set's coordinates in it.
    let spectral = match (config.model.spectral_basis, &offset) {
        (Some(size), Some(mean)) => {
            progress.status(&format!("fitting {size} principal directions"));
            let mut fit = crate::principal::fit_basis(data, mean, size)?;
            if state.epoch == 0 && state.batch == 0 {
                model = model.with_basis(&fit.basis)?;
            }
            fit.basis = Vec::new(); // in the model now; only the coordinates are needed
            Some(fit)
        }
        _ => None,
    };
    // Without convolutions, training runs on the coordinates alone (see `crate::spectral`).
    let coefficients = spectral.filter(|_| config.model.spectral_only());
    let pretty = serde_json::to_string_pretty(&config_json).unwrap_or_default();
    write_atomic(&out_dir.join(CONFIG_FILE), &[pretty.as_bytes(), b"\n"])?;

    let n = data.len();
    let batches_per_epoch = n.div_ceil(config.batch_size);
    let total_steps = batches_per_epoch * config.epochs;
    let done = state.epoch * n + (state.batch * config.batch_size).min(n);
    let remaining = (config.epochs * n).saturating_sub(done) as u64;
    if remaining > 0 {
        progress.start(remaining, &format!("training k={}", config.model.latent));
    }
    let dropout = match &config.slice_dropout {
        Some(d) => Some((d.probability, d.parsed()?)),
        None => None,
    };
    // On coordinates, slice dropout uses the coordinates of the filled inputs, computed once.
    let dropout_coefficients = match (&coefficients, &dropout, &offset) {
        (Some(_), Some((_, selections)), Some(mean)) => {
            progress.status("projecting the slice-dropout inputs");
            Some(filled_coefficients(&model, data, mean, selections, config.seed)?)
        }
        _ => None,
    };
    let mut last_checkpoint = Instant::now();
    while state.epoch < config.epochs {
        let order = epoch_order(config.seed, state.epoch, n);
        let mut lr = config.learning_rate_at(state.epoch * batches_per_epoch, total_steps);
        while state.batch < batches_per_epoch {
            let started = Instant::now();
            let start = state.batch * config.batch_size;
            let indices = &order[start..(start + config.batch_size).min(n)];
            let augment = dropout.as_ref().map(|(p, selections)| Augment {
                probability: *p,
                selections,
                seed: config.seed,
                epoch: state.epoch,
            });
            let (value, grads) = match &coefficients {
                Some(fit) => {
                    let inputs: Vec<f32> = indices
                        .iter()
                        .flat_map(|&i| {
                            let choice = augment.as_ref().and_then(|a| a.choice(i));
                            match (&dropout_coefficients, choice) {
                                (Some(filled), Some(s)) => filled[i][s].clone(),
                                _ => fit.coefficients[i].clone(),
                            }
                        })
                        .collect();
                    coefficient_gradients(&model, data, fit, indices, inputs, &autodiff)?
                }
                None => gradients(
                    &model,
                    data,
                    indices,
                    augment.as_ref(),
                    offset.as_deref(),
                    config.threads,
                    &autodiff,
                ),
            };
            if !value.is_finite() {
                progress.finish();
                let kept = if checkpoint.exists() {
                    format!(
                        "the last good checkpoint ({} epochs + {} batches) is kept in {}",
                        state.epoch,
                        state.batch,
                        checkpoint.display()
                    )
                } else {
                    "no checkpoint had been written yet".to_string()
                };
                return Err(ModelError::NonFinite {
                    loss: value,
                    epoch: state.epoch + 1,
                    batch: state.batch + 1,
                    kept,
                    suggested_lr: config.learning_rate / 10.0,
                });
            }
            lr =
                config.learning_rate_at(state.epoch * batches_per_epoch + state.batch, total_steps);
            model = optim.step_multi(lr, model, grads);
            if kill_after == Some((state.epoch, state.batch)) {
                return Err(ModelError::Invalid("killed (test)".into()));
            }
            state.loss_sum += f64::from(value) * indices.len() as f64;
            state.samples += indices.len();
            state.batch += 1;
            let seconds = started.elapsed().as_secs_f64();
            state.epoch_seconds += seconds;
            state.total_seconds += seconds;
            progress.advance(indices.len() as u64);
            progress.status(&format!(
                "epoch {}/{} loss {:.3e}",
                state.epoch + 1,
                config.epochs,
                state.loss_sum / state.samples.max(1) as f64
            ));
            let epoch_done = state.batch == batches_per_epoch;
            if !epoch_done && last_checkpoint.elapsed().as_secs_f64() >= config.checkpoint_seconds {
                save_checkpoint(&checkpoint, &model, &optim, &state)?;
                last_checkpoint = Instant::now();
            }
        }
        state.log.push(EpochRecord {
            epoch: state.epoch + 1,
            loss: state.loss_sum / state.samples.max(1) as f64,
            learning_rate: lr,
            seconds: state.epoch_seconds,
        });
        state.epoch += 1;
        state.batch = 0;
        state.loss_sum = 0.0;
        state.samples = 0;
        state.epoch_seconds = 0.0;
        // Every `checkpoint_seconds` and at the end (epochs of the spectral preset take
        // milliseconds; its checkpoint holds a ~1 GB basis).
        let last = state.epoch == config.epochs;
        if last || last_checkpoint.elapsed().as_secs_f64() >= config.checkpoint_seconds {
            save_checkpoint(&checkpoint, &model, &optim, &state)?;
            last_checkpoint = Instant::now();
        }
        write_log(&out_dir.join(LOG_FILE), &state.log)?;
    }
    if remaining > 0 {
        progress.finish();
    }
    let model = model.valid();
    let per_material_mse = evaluate(&model, data, config.batch_size, progress)?;
    Ok(Trained {
        model,
        config: config.clone(),
        log: state.log,
        seconds: state.total_seconds,
        data_fingerprint: fingerprint,
        per_material_mse,
    })
}

/// The mapped-space MSE over valid values of each BRDF of `data` (eq. 4 per BRDF), with the
/// network in inference mode.
pub fn evaluate(
    model: &Autoencoder,
    data: &TrainingSet,
    batch_size: usize,
    progress: &dyn Progress,
) -> crate::error::Result<Vec<f64>> {
    let model = model.valid();
    let device = model.devices().into_iter().next().unwrap_or_default().without_autodiff();
    let offset = model.offset();
    let mut errors = Vec::with_capacity(data.len());
    let indices: Vec<usize> = (0..data.len()).collect();
    progress.start(data.len() as u64, "evaluating");
    for chunk in indices.chunks(batch_size.max(1)) {
        let b = batch_tensors(data, chunk, None, offset.as_deref(), &device);
        let deviation = model.decode_deviation(model.encode_centred(b.input));
        let batch = chunk.len();
        let diff = deviation * b.mask - b.target; // [batch, 540, 90, 90]
        let sq = (diff.clone() * diff).reshape([batch, INPUT_VALUES]).sum_dim(1); // [batch, 1]
        let sq: Vec<f32> = sq.into_data().try_into_vec().map_err(tensor_error)?;
        for (s, v) in sq.iter().zip(&b.valid) {
            errors.push(f64::from(*s) / v.max(1.0));
        }
        progress.advance(batch as u64);
    }
    progress.finish();
    Ok(errors)
}

fn tensor_error(e: impl std::fmt::Debug) -> ModelError {
    ModelError::Invalid(format!("reading a tensor back failed: {e:?}"))
}

/// The order of the BRDFs in epoch `epoch` (0-based): a permutation depending only on the
/// seed and the epoch.
pub fn epoch_order(seed: u64, epoch: usize, n: usize) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(epoch as u64);
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(&mut rng);
    order
}

/// Slice dropout applied to one batch.
pub(crate) struct Augment<'a> {
    probability: f64,
    selections: &'a [SliceSelection],
    seed: u64,
    epoch: usize,
}

impl Augment<'_> {
    /// The kept slices for BRDF `index` in this epoch, or `None` to show it whole; a function of
    /// (seed, epoch, index) only, so resumed runs draw the same.
    fn kept(&self, index: usize) -> Option<Vec<usize>> {
        let (selection, mut rng) = self.draw(index)?;
        Some(kept_slices(&self.selections[selection], rng.random()))
    }

    /// Which selection BRDF `index` is shown with in this epoch (the same draw as
    /// [`kept`](Self::kept)), or `None` to show it whole.
    fn choice(&self, index: usize) -> Option<usize> {
        self.draw(index).map(|(selection, _)| selection)
    }

    fn draw(&self, index: usize) -> Option<(usize, ChaCha8Rng)> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ 0x51ce_d20f_0a5e_u64);
        rng.set_stream(((self.epoch as u64) << 32) | index as u64);
        if rng.random::<f64>() >= self.probability {
            return None;
        }
        let selection = rng.random_range(0..self.selections.len());
        Some((selection, rng))
    }
}

/// One training batch, prepared on the CPU: inputs and targets centred on the fixed offset
/// and masked, `(x - mu) * mask` (just `x * mask` without an offset), as
/// [`masked_mse_centred`] expects.
pub(crate) struct Batch {
    /// `[batch, 540, 90, 90]`: the network's input (with slice dropout, the filled one).
    input: Tensor<4>,
    /// `[batch, 540, 90, 90]`: the centred, masked target.
    target: Tensor<4>,
    /// `[batch, 540, 90, 90]`
    mask: Tensor<4>,
    /// Valid values of each BRDF.
    valid: Vec<f64>,
}

/// The eq. (4) loss of a batch, its squared error divided by `valid` (the valid values of the
/// whole batch when this is a shard of it): the forward step training and benchmarks share.
pub(crate) fn batch_loss(model: &Autoencoder, batch: Batch, valid: f64) -> Tensor<1> {
    let deviation = model.decode_deviation(model.encode_centred(batch.input)); // [batch, 540, 90, 90]
    masked_mse_centred(deviation, batch.target, batch.mask, valid) // [1]
}

/// The loss and gradients of the batch `indices`, computed in `threads` shards in parallel
/// (Burn's CPU backends as built here run each operation on one core; shards put both cores
/// to work). Each shard works on its own fork of the model (its own autodiff graph); the
/// optimizer sums the shards' gradients, each normalised by the whole batch's valid values,
/// so the step is that of the whole batch. Deterministic for a given `threads`.
pub(crate) fn gradients(
    model: &Autoencoder,
    data: &TrainingSet,
    indices: &[usize],
    augment: Option<&Augment>,
    offset: Option<&[f32]>,
    threads: usize,
    device: &Device,
) -> (f32, MultiGradientsParams) {
    let valid: f64 = indices.iter().map(|&i| data.valid_values(i)).sum();
    let shard = |indices: &[usize], forked: bool| {
        let model = if forked { model.clone().fork(device) } else { model.clone() };
        let batch = batch_tensors(data, indices, augment, offset, device);
        let loss = batch_loss(&model, batch, valid);
        let value: f32 = loss.clone().into_scalar();
        (value, GradientsParams::from_grads(loss.backward(), &model))
    };
    let shards: Vec<&[usize]> = indices.chunks(indices.len().div_ceil(threads.max(1))).collect();
    let results: Vec<(f32, GradientsParams)> = if shards.len() == 1 {
        vec![shard(shards[0], false)]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> =
                shards.iter().map(|&s| scope.spawn(move || shard(s, true))).collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        })
    };
    let mut total = 0f32;
    let mut grads = MultiGradientsParams::default();
    for (value, g) in results {
        total += value;
        grads.grads.push((g, device.clone()));
    }
    (total, grads)
}

/// The eq. (4) loss of the batch `indices` and its gradients, computed on the spectral
/// coordinates of a network without convolutions: for orthonormal basis rows, the squared error
/// of a training BRDF is `|c_hat - c|^2` plus its (fixed) distance to the basis' span.
pub(crate) fn coefficient_gradients(
    model: &Autoencoder,
    data: &TrainingSet,
    fit: &crate::principal::PrincipalFit,
    indices: &[usize],
    inputs: Vec<f32>,
    device: &Device,
) -> crate::error::Result<(f32, MultiGradientsParams)> {
    let path = model
        .spectral()
        .ok_or_else(|| ModelError::Invalid("coefficient training needs a spectral path".into()))?;
    let size = path.size();
    let valid: f64 = indices.iter().map(|&i| data.valid_values(i)).sum();
    let residual: f64 = indices.iter().map(|&i| fit.residuals[i]).sum();
    let values: Vec<f32> = indices.iter().flat_map(|&i| fit.coefficients[i].clone()).collect();
    let c = Tensor::<2>::from_data(TensorData::new(values, [indices.len(), size]), device);
    let input = Tensor::<2>::from_data(TensorData::new(inputs, [indices.len(), size]), device);
    let diff = path.decode(path.encode(input)) - c; // [batch, K]
    let loss = (diff.clone() * diff).sum().div_scalar(valid.max(1.0)); // [1]
    let value: f32 = loss.clone().into_scalar();
    let value = value + (residual / valid.max(1.0)) as f32;
    let grads = GradientsParams::from_grads(loss.backward(), model);
    let mut multi = MultiGradientsParams::default();
    multi.grads.push((grads, device.clone()));
    Ok((value, multi))
}

/// The spectral coordinates of every BRDF of `data` with only the slices of each selection
/// (the missing ones filled from their nearest kept one), `[brdf][selection][K]`; the kept
/// slices of a random selection are drawn once per (seed, BRDF, selection).
fn filled_coefficients(
    model: &Autoencoder,
    data: &TrainingSet,
    offset: &[f32],
    selections: &[SliceSelection],
    seed: u64,
) -> crate::error::Result<Vec<Vec<Vec<f32>>>> {
    let model = model.valid();
    let path = model
        .spectral()
        .ok_or_else(|| ModelError::Invalid("coefficient training needs a spectral path".into()))?;
    let device = model.devices().into_iter().next().unwrap_or_default();
    let mut out = vec![Vec::with_capacity(selections.len()); data.len()];
    for (i, slot) in out.iter_mut().enumerate() {
        let mut rows = vec![0f32; selections.len() * INPUT_VALUES];
        for (s, selection) in selections.iter().enumerate() {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xf111_ed5e_u64);
            rng.set_stream(((i as u64) << 16) | s as u64);
            let mut filled = data.input(i).to_vec();
            fill_missing_layout(&mut filled, &kept_slices(selection, rng.random()));
            let row = &mut rows[s * INPUT_VALUES..(s + 1) * INPUT_VALUES];
            centre(row, &filled, data.mask(i), Some(offset));
        }
        let rows = Tensor::<2>::from_data(
            TensorData::new(rows, [selections.len(), INPUT_VALUES]),
            &device,
        );
        let c: Vec<f32> =
            path.coefficients(rows).into_data().try_into_vec().map_err(tensor_error)?;
        *slot = c.chunks(path.size()).map(<[f32]>::to_vec).collect();
    }
    Ok(out)
}

/// Writes `(x - offset) * mask` into `out`, in parallel.
fn centre(out: &mut [f32], x: &[f32], mask: &[f32], offset: Option<&[f32]>) {
    const CHUNK: usize = 1 << 16;
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, o)| {
        let range = c * CHUNK..c * CHUNK + o.len();
        let (x, m) = (&x[range.clone()], &mask[range.clone()]);
        match offset {
            Some(mu) => {
                for (((o, &x), &m), &mu) in o.iter_mut().zip(x).zip(m).zip(&mu[range]) {
                    *o = (x - mu) * m;
                }
            }
            None => {
                for ((o, &x), &m) in o.iter_mut().zip(x).zip(m) {
                    *o = x * m;
                }
            }
        }
    });
}

/// Stacks BRDFs `indices` of `data` into a [`Batch`] on `device`.
pub(crate) fn batch_tensors(
    data: &TrainingSet,
    indices: &[usize],
    augment: Option<&Augment>,
    offset: Option<&[f32]>,
    device: &Device,
) -> Batch {
    let shape = [indices.len(), INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
    let len = indices.len() * INPUT_VALUES;
    let mut target = vec![0f32; len];
    let mut mask = vec![0f32; len];
    let mut input: Option<Vec<f32>> = None;
    let mut valid = Vec::with_capacity(indices.len());
    for (slot, &i) in indices.iter().enumerate() {
        let range = slot * INPUT_VALUES..(slot + 1) * INPUT_VALUES;
        centre(&mut target[range.clone()], data.input(i), data.mask(i), offset);
        mask[range.clone()].copy_from_slice(data.mask(i));
        valid.push(data.mask(i).iter().map(|&m| f64::from(m)).sum());
        if let Some(kept) = augment.and_then(|a| a.kept(i)) {
            let input = input.get_or_insert_with(|| target.clone());
            let mut filled = data.input(i).to_vec();
            fill_missing_layout(&mut filled, &kept);
            centre(&mut input[range], &filled, data.mask(i), offset);
        } else if let Some(input) = input.as_mut() {
            input[range.clone()].copy_from_slice(&target[range]);
        }
    }
    let target = Tensor::from_data(TensorData::new(target, shape), device);
    let input = match input {
        Some(input) => Tensor::from_data(TensorData::new(input, shape), device),
        None => target.clone(),
    };
    Batch { input, target, mask: Tensor::from_data(TensorData::new(mask, shape), device), valid }
}

fn save_checkpoint(
    path: &Path,
    model: &Autoencoder,
    optim: &burn::optim::ModuleOptimizer,
    state: &TrainState,
) -> crate::error::Result<()> {
    let record_error = |e: burn::store::RecordError| ModelError::format(path, e.to_string());
    let mut c = Container::new();
    let state_json = serde_json::to_vec(state)
        .map_err(|e| ModelError::Invalid(format!("cannot serialise the training state: {e}")))?;
    c.push("state", state_json);
    c.push("model", model.clone().into_record().into_bytes().map_err(record_error)?.to_vec());
    c.push("optimizer", optim.into_bytes().map_err(record_error)?.to_vec());
    c.save(path, CHECKPOINT_KIND)
}

fn load_checkpoint(
    path: &Path,
    config: &TrainConfig,
    config_json: &serde_json::Value,
    fingerprint: &str,
    device: &Device,
) -> crate::error::Result<(Autoencoder, burn::optim::ModuleOptimizer, TrainState)> {
    let mut c = Container::load(path, CHECKPOINT_KIND)?;
    let missing = |what: &str| ModelError::format(path, format!("the checkpoint has no {what}"));
    let state: TrainState = serde_json::from_slice(c.get("state").ok_or_else(|| missing("state"))?)
        .map_err(|e| ModelError::format(path, format!("bad training state: {e}")))?;
    if !json_close(&state.config, config_json) {
        return Err(ModelError::mismatch(
            path,
            format!(
                "the checkpoint was written with another configuration; resume with the same \
                 settings (saved in {CONFIG_FILE}: {})",
                state.config
            ),
        ));
    }
    if state.data_fingerprint != fingerprint {
        return Err(ModelError::mismatch(
            path,
            "the checkpoint was trained on other data (the data fingerprint differs)",
        ));
    }
    let record_error = |e: burn::store::RecordError| ModelError::format(path, e.to_string());
    let model_bytes = c.take("model").ok_or_else(|| missing("model"))?;
    let record =
        ModuleRecord::from_bytes(Bytes::from_bytes_vec(model_bytes)).map_err(record_error)?;
    let model = config.model.init(device)?.try_load_record(record).map_err(record_error)?;
    let optim_bytes = c.take("optimizer").ok_or_else(|| missing("optimizer"))?;
    let optim = config
        .optimizer
        .init()
        .from_bytes(Bytes::from_bytes_vec(optim_bytes))
        .map_err(record_error)?;
    Ok((model, optim, state))
}

/// Whether two JSON values are equal, numbers up to a relative 1e-9 (a number printed and
/// parsed again by serde_json may come back one unit in the last place away).
pub fn json_close(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => x == y || (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| json_close(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| json_close(v, w)))
        }
        _ => a == b,
    }
}

/// The configuration of the run saved in `out_dir` (from its checkpoint), to resume it.
pub fn saved_config(out_dir: &Path) -> crate::error::Result<TrainConfig> {
    let path = out_dir.join(CHECKPOINT_FILE);
    let c = Container::load(&path, CHECKPOINT_KIND)?;
    let state = c.get("state").ok_or_else(|| ModelError::format(&path, "no training state"))?;
    let state: TrainState = serde_json::from_slice(state)
        .map_err(|e| ModelError::format(&path, format!("bad training state: {e}")))?;
    serde_json::from_value(state.config)
        .map_err(|e| ModelError::format(&path, format!("bad configuration: {e}")))
}

fn write_log(path: &Path, log: &[EpochRecord]) -> crate::error::Result<()> {
    let mut csv = String::from("epoch,loss,learning_rate,seconds\n");
    for r in log {
        csv.push_str(&format!(
            "{},{:.6e},{:.6e},{:.3}\n",
            r.epoch, r.loss, r.learning_rate, r.seconds
        ));
    }
    write_atomic(path, &[csv.as_bytes()])
}

/// The training directory's checkpoint path.
pub fn checkpoint_path(out_dir: &Path) -> PathBuf {
    out_dir.join(CHECKPOINT_FILE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autoencoder::INPUT_VALUES;
    use crate::device::DeviceKind;
    use deepbrdf_data::Silent;

    /// A network with Table 1's strides and kernels but one or two channels per layer.
    fn tiny_config(mean_offset: bool) -> TrainConfig {
        let model = AutoencoderConfig::new()
            .with_latent(2)
            .with_projection(Some(2))
            .with_encoder_channels([2, 2, 2])
            .with_residual_blocks(1)
            .with_decoder_channels([2, 2])
            .with_mean_offset(mean_offset);
        TrainConfig::new(model, AdamConfig::new())
            .with_learning_rate(3e-2)
            .with_epochs(6)
            .with_batch_size(2)
            .with_seed(7)
            .with_checkpoint_seconds(0.0)
    }

    /// Smooth synthetic layouts: a per-BRDF level and slope over theta_h rows, invalid cells
    /// (a corner of each image) masked.
    fn tiny_set(n: usize) -> TrainingSet {
        let mut inputs = Vec::new();
        let mut masks = Vec::new();
        for b in 0..n {
            let level = 0.5 + 0.3 * b as f32;
            let mut input = vec![0f32; INPUT_VALUES];
            let mut mask = vec![0f32; INPUT_VALUES];
            for (i, (v, m)) in input.iter_mut().zip(mask.iter_mut()).enumerate() {
                let row = (i / INPUT_SIDE) % INPUT_SIDE;
                let col = i % INPUT_SIDE;
                if row + col < 150 {
                    *m = 1.0;
                    *v = level + 0.01 * row as f32 * (1.0 + b as f32);
                }
            }
            inputs.push(input);
            masks.push(mask);
        }
        let names = (0..n).map(|b| format!("synthetic-{b}")).collect();
        TrainingSet::from_layouts("synthetic", names, inputs, masks).unwrap()
    }

    #[test]
    fn the_loss_falls_on_every_compiled_backend() {
        let set = tiny_set(2);
        let config = tiny_config(false).with_epochs(8).with_batch_size(1).with_learning_rate(5e-2);
        for kind in DeviceKind::available() {
            if matches!(kind, DeviceKind::Wgpu | DeviceKind::Cuda) {
                continue; // GPU backends are exercised on GPU machines, not in CI.
            }
            let device = kind.device().unwrap();
            let dir = tempfile::tempdir().unwrap();
            let trained = train(&config, &set, dir.path(), false, &Silent, &device).unwrap();
            let first = trained.log.first().unwrap().loss;
            let last = trained.log.last().unwrap().loss;
            assert!(last < 0.7 * first, "{kind}: loss {first} -> {last}");
            assert_eq!(trained.log.len(), 8);
            assert!(trained.mean_mse() < 0.7 * first, "{kind}: {}", trained.mean_mse());
            let csv = std::fs::read_to_string(dir.path().join(LOG_FILE)).unwrap();
            assert_eq!(csv.lines().count(), 9, "{csv}");
            assert_eq!(saved_config(dir.path()).unwrap().to_string(), config.to_string());
        }
    }

    #[test]
    fn spectral_training_on_coordinates_matches_the_full_loss() {
        // The coordinate loss (plus the distance to the basis' span) is eq. (4) on the full
        // tensors: after training, the logged loss of the last epoch (the model barely moves at
        // the end of the cosine decay) agrees with a full-space evaluation of the trained model.
        // Four BRDFs spanning three directions: k = 1 leaves a linear fit far from exact.
        let pattern = |i: usize| {
            [((i % 7) as f32 - 3.0) / 3.0, ((i % 5) as f32 - 2.0) / 2.0, (i % 3) as f32 - 1.0]
        };
        let mix = [[1.0, 0.0, 0.3], [-0.5, 1.0, -0.2], [-0.5, -1.0, 0.4], [0.2, 0.4, -0.9]];
        let mask: Vec<f32> =
            (0..INPUT_VALUES).map(|i| if i % 11 == 0 { 0.0 } else { 1.0 }).collect();
        let inputs: Vec<Vec<f32>> = mix
            .iter()
            .map(|w| {
                (0..INPUT_VALUES)
                    .map(|i| {
                        let p = pattern(i);
                        (1.0 + w[0] * p[0] + w[1] * p[1] + w[2] * p[2]) * mask[i]
                    })
                    .collect()
            })
            .collect();
        let names = (0..4).map(|b| format!("mixed-{b}")).collect();
        let set = TrainingSet::from_layouts("mixed", names, inputs, vec![mask; 4]).unwrap();
        let model = AutoencoderConfig::spectral(1, 3, Some(16));
        let config = TrainConfig::new(model, adam())
            .with_learning_rate(2e-2)
            .with_final_lr_factor(0.01)
            .with_epochs(500)
            .with_batch_size(4)
            .with_seed(3)
            .with_checkpoint_seconds(1e6); // at the end only: each holds the 52 MB basis
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let trained = train(&config, &set, dir.path(), false, &Silent, &device).unwrap();
        let (first, last) = (trained.log[0].loss, trained.log.last().unwrap().loss);
        assert!(last < 0.7 * first, "loss {first} -> {last}");
        let full = trained.mean_mse();
        assert!((full - last).abs() <= 1e-2 * full, "coordinates {last} vs full {full}");
        // With slice dropout (on the coordinates of filled inputs) training still fits.
        let dropout = config.clone().with_slice_dropout(Some(SliceDropoutConfig::new()));
        let other = tempfile::tempdir().unwrap();
        let augmented = train(&dropout, &set, other.path(), false, &Silent, &device).unwrap();
        assert!(augmented.log.last().unwrap().loss < 0.9 * augmented.log[0].loss);
    }

    #[test]
    fn a_killed_run_resumes_to_the_same_result() {
        // 2 batches per epoch, the last one short. One shard per batch: with two shards this
        // test failed once in five runs on a loaded machine (the losses after resuming differed),
        // so exact resumption is only claimed for the serial path until that is understood.
        let set = tiny_set(3);
        let config = tiny_config(true).with_epochs(2).with_final_lr_factor(0.1).with_threads(1);
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let straight_dir = tempfile::tempdir().unwrap();
        let straight = train(&config, &set, straight_dir.path(), false, &Silent, &device).unwrap();

        let dir = tempfile::tempdir().unwrap();
        // Killed in the middle of epoch 2: its first batch is applied but never saved.
        let killed = run(&config, &set, dir.path(), false, &Silent, &device, Some((1, 0)));
        assert!(killed.is_err());
        // Without `resume`, an existing run is never overwritten.
        assert!(train(&config, &set, dir.path(), false, &Silent, &device).is_err());
        // Another configuration cannot continue it.
        let other = config.clone().with_learning_rate(1e-3);
        let err = train(&other, &set, dir.path(), true, &Silent, &device).unwrap_err();
        assert!(err.to_string().contains("configuration"), "{err}");
        let resumed = train(&config, &set, dir.path(), true, &Silent, &device).unwrap();

        let losses = |t: &Trained| t.log.iter().map(|r| (r.epoch, r.loss)).collect::<Vec<_>>();
        assert_eq!(losses(&resumed), losses(&straight));
        assert_eq!(resumed.per_material_mse, straight.per_material_mse);
        // A finished run resumes to itself.
        let again = train(&config, &set, dir.path(), true, &Silent, &device).unwrap();
        assert_eq!(again.per_material_mse, straight.per_material_mse);
    }

    #[test]
    fn a_damaged_checkpoint_is_reported_not_used() {
        let set = tiny_set(2);
        let config = tiny_config(false).with_epochs(1);
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let dir = tempfile::tempdir().unwrap();
        train(&config, &set, dir.path(), false, &Silent, &device).unwrap();
        let path = dir.path().join(CHECKPOINT_FILE);
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let err = train(&config, &set, dir.path(), true, &Silent, &device).unwrap_err();
        assert!(err.to_string().contains("checkpoint.bin"), "{err}");
    }

    #[test]
    fn a_diverging_run_stops_and_keeps_its_last_checkpoint() {
        // Values of 3e19 square to more than f32::MAX: the first loss is infinite.
        let set = tiny_set(2);
        let huge = TrainingSet::from_layouts(
            "huge",
            set.names().to_vec(),
            vec![vec![3e19; INPUT_VALUES]; 2],
            vec![set.mask(0).to_vec(), set.mask(1).to_vec()],
        )
        .unwrap();
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let err =
            train(&tiny_config(false), &huge, dir.path(), false, &Silent, &device).unwrap_err();
        assert!(matches!(err, ModelError::NonFinite { epoch: 1, batch: 1, .. }), "{err}");
        assert!(err.to_string().contains("no checkpoint"), "{err}");
    }

    #[test]
    fn epoch_orders_are_seeded_permutations() {
        let a = epoch_order(1, 0, 10);
        assert_eq!(a, epoch_order(1, 0, 10));
        assert_ne!(a, epoch_order(1, 1, 10));
        assert_ne!(a, epoch_order(2, 0, 10));
        let mut sorted = a.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..10).collect::<Vec<_>>());
    }

    #[test]
    fn the_learning_rate_decays_along_a_half_cosine() {
        let c = tiny_config(false).with_learning_rate(1.0).with_final_lr_factor(0.1);
        assert!((c.learning_rate_at(0, 11) - 1.0).abs() < 1e-12);
        assert!((c.learning_rate_at(5, 11) - 0.55).abs() < 1e-12);
        assert!((c.learning_rate_at(10, 11) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn slice_dropout_fills_inputs_but_keeps_targets() {
        // Every layout channel holds its own index, so a filled slice is visible.
        let plane = INPUT_SIDE * INPUT_SIDE;
        let layout: Vec<f32> = (0..INPUT_VALUES).map(|i| (i / plane) as f32).collect();
        let set = TrainingSet::from_layouts(
            "channels",
            vec!["a".into(), "b".into()],
            vec![layout.clone(), layout],
            vec![vec![1.0; INPUT_VALUES]; 2],
        )
        .unwrap();
        let device = DeviceKind::default_kind().unwrap().device().unwrap();
        let selections = [SliceSelection::Every(9)];
        let augment = Augment { probability: 1.0, selections: &selections, seed: 3, epoch: 0 };
        let b = batch_tensors(&set, &[1], Some(&augment), None, &device);
        let input: Vec<f32> = b.input.into_data().try_into_vec().unwrap();
        let target: Vec<f32> = b.target.into_data().try_into_vec().unwrap();
        assert_eq!(target, set.input(1));
        // Slice 1 (channels 3..6) is filled from slice 0 (every 9th slice from 0 is kept).
        let slice = 3 * INPUT_SIDE * INPUT_SIDE;
        assert_eq!(input[slice..2 * slice], input[..slice]);
        assert_ne!(input[slice..2 * slice], target[slice..2 * slice]);
        // Slice 9 is kept.
        assert_eq!(input[9 * slice..10 * slice], target[9 * slice..10 * slice]);
        let dropout = SliceDropoutConfig::new().with_selections(vec!["every:0".into()]);
        assert!(dropout.parsed().is_err());
    }
}

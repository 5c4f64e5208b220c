//! The training loop every network shares ([`run`]): epochs of seeded batches, the
//! network-specific step ([`TrainStep`]: loss and gradients of a batch), Adam with the
//! learning-rate schedule, the NaN stop, checkpoints and exact resume, the CSV log, progress.
//!
//! Not Burn's `burn-train` `Learner`: a run here must resume from a checkpoint taken within an
//! epoch to the same bits (seeded per-epoch orders, the batch position and the optimizer state
//! saved together), stop on a non-finite loss keeping the last good checkpoint, and let a step
//! train on what it prepared itself (the slice network's coefficients) rather than on a
//! dataloader's items; this loop does that in a few hundred lines.

use std::fs;
use std::path::Path;
use std::time::{Duration, Instant};

use burn::module::Module;
use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use deepbrdf_data::Progress;

use super::checkpoint::{self, TrainState, CONFIG_FILE};
use super::config::LoopConfig;
use super::divergence::check_finite;
use super::log::{write_log, EpochRecord, LOG_FILE};
use super::order::{batch_of, batches_per_epoch, epoch_order};
use super::progress::RunProgress;
use crate::artifact::files::write_atomic;
use crate::error::{ModelError, Result};

/// What a network brings to the loop: how to build it and the loss and gradients of a batch.
///
/// The loop owns everything else; a step only sees example indices (into whatever data the
/// implementor holds) and the epoch, so it can draw per-epoch augmentation from them.
pub trait TrainStep {
    /// The network (on an autodiff device).
    type Model: Module;

    /// The network of a new run, freshly initialised (reproducibly, e.g. with
    /// [`crate::seeded::with_seed`] and the loop's seed).
    fn init(&mut self, device: &Device) -> Result<Self::Model>;

    /// A network of the run's configuration to load a checkpoint into (its values do not
    /// matter); by default [`init`](Self::init).
    fn skeleton(&mut self, device: &Device) -> Result<Self::Model> {
        self.init(device)
    }

    /// Called once before the first step, with the new (`fresh`) or resumed network: work the
    /// steps need that is not saved in checkpoints (it must be deterministic). By default
    /// nothing.
    fn prepare(
        &mut self,
        model: Self::Model,
        _fresh: bool,
        _progress: &dyn Progress,
    ) -> Result<Self::Model> {
        Ok(model)
    }

    /// The mean loss of the examples `indices` (a batch of epoch `epoch`, 0-based) and its
    /// gradients ([`on_device`] wraps those of one device).
    fn step(
        &mut self,
        model: &Self::Model,
        epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> Result<(f32, MultiGradientsParams)>;
}

/// The gradients of one device, as [`TrainStep::step`] returns them.
pub fn on_device(grads: GradientsParams, device: &Device) -> MultiGradientsParams {
    let mut multi = MultiGradientsParams::default();
    multi.grads.push((grads, device.clone()));
    multi
}

/// Where a run keeps its files and how it reports.
pub struct Session<'a> {
    dir: &'a Path,
    resume: bool,
    progress: &'a dyn Progress,
    label: String,
    /// Stop at the end of the first epoch that ends this long after the run started (the
    /// checkpoint then resumes it).
    time_limit: Option<Duration>,
    /// Tests: stop as if killed right after batch `(epoch, batch)` (0-based) was applied and
    /// before anything was written for it.
    kill_after: Option<(usize, usize)>,
}

impl<'a> Session<'a> {
    /// A run kept in `dir` (checkpoint, configuration, log), reporting to `progress` under
    /// `label`. With `resume`, a checkpoint in `dir` is continued exactly where it stopped (it
    /// must have been written with the same configuration and data); without one the run
    /// starts afresh. Without `resume`, an existing checkpoint is an error: nothing is
    /// overwritten.
    pub fn new(dir: &'a Path, resume: bool, progress: &'a dyn Progress, label: &str) -> Self {
        Self { dir, resume, progress, label: label.to_string(), time_limit: None, kill_after: None }
    }

    /// Stops the run at the end of the first epoch that ends `limit` after it started, with a
    /// checkpoint, so a machine lent for a bounded time trains as far as it can and a later
    /// `resume` continues exactly there. The network returned then has the epochs done so far
    /// ([`Outcome::log`]). `None`: no limit.
    pub fn with_time_limit(mut self, limit: Option<Duration>) -> Self {
        self.time_limit = limit;
        self
    }

    /// The run's directory.
    pub fn dir(&self) -> &Path {
        self.dir
    }

    /// Whether an interrupted run in the directory is continued.
    pub fn resumes(&self) -> bool {
        self.resume
    }

    /// Where the run reports.
    pub fn progress(&self) -> &dyn Progress {
        self.progress
    }

    #[cfg(test)]
    pub(crate) fn killed_after(mut self, epoch: usize, batch: usize) -> Self {
        self.kill_after = Some((epoch, batch));
        self
    }
}

/// The result of [`run`]: the network after all the configured epochs, or after those done
/// within the session's time limit (then `log` is shorter than the configuration's epochs).
#[derive(Debug)]
pub struct Outcome<M> {
    /// The trained network (still on the autodiff device; `valid()` for inference).
    pub model: M,
    /// The per-epoch log.
    pub log: Vec<EpochRecord>,
    /// Seconds spent training (over all resumed pieces).
    pub seconds: f64,
}

/// Trains `step`'s network on `examples` examples with `config`, in `session`'s directory.
///
/// `identity` is the run's whole configuration (saved as [`CONFIG_FILE`] and in checkpoints; a
/// checkpoint resumes only under the same one) and `fingerprint` a digest of the data (the
/// same). A run whose checkpoint has all its epochs returns its network without a step.
///
/// Deterministic: the order of each epoch depends only on the seed and the epoch
/// ([`super::order`]), so a resumed run replays the same batches and, with a deterministic
/// step and backend, reaches the same weights as an uninterrupted one.
pub fn run<S: TrainStep>(
    config: &LoopConfig,
    identity: &serde_json::Value,
    fingerprint: &str,
    examples: usize,
    step: &mut S,
    session: &Session<'_>,
    device: &Device,
) -> Result<Outcome<S::Model>> {
    config.validate()?;
    if examples == 0 {
        return Err(ModelError::Invalid("training needs at least one example".into()));
    }
    let dir = session.dir;
    fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
    let checkpoint = checkpoint::checkpoint_path(dir);
    let autodiff = device.clone().autodiff();
    let fresh = !checkpoint.exists();
    let (model, mut optim, mut state) = if fresh {
        let model = step.init(&autodiff)?;
        let state = TrainState::fresh(identity.clone(), fingerprint.to_string());
        (model, config.optimizer.init(), state)
    } else {
        if !session.resume {
            return Err(ModelError::Invalid(format!(
                "{} already holds a training run ({}); resume it or choose another output \
                 directory",
                dir.display(),
                checkpoint::CHECKPOINT_FILE
            )));
        }
        let skeleton = step.skeleton(&autodiff)?;
        checkpoint::load(&checkpoint, identity, fingerprint, skeleton, config.optimizer.init())?
    };
    let mut model = step.prepare(model, fresh, session.progress)?;
    let pretty = serde_json::to_string_pretty(identity).unwrap_or_default();
    write_atomic(&dir.join(CONFIG_FILE), &[pretty.as_bytes(), b"\n"])?;

    let batches = batches_per_epoch(examples, config.batch_size);
    let total_steps = batches * config.epochs;
    let mut progress = RunProgress::start(
        session.progress,
        &session.label,
        &state,
        config.epochs,
        examples,
        config.batch_size,
    );
    let mut last_checkpoint = Instant::now();
    let deadline = session.time_limit.map(|limit| Instant::now() + limit);
    while state.epoch < config.epochs {
        let order = epoch_order(config.seed, state.epoch, examples);
        let mut lr = config.learning_rate_at(state.epoch * batches, total_steps);
        while state.batch < batches {
            let started = Instant::now();
            let indices = batch_of(&order, state.batch, config.batch_size);
            let (value, grads) = step.step(&model, state.epoch, indices, &autodiff)?;
            if let Err(e) = check_finite(value, &state, &checkpoint, config.learning_rate) {
                progress.finish();
                return Err(e);
            }
            lr = config.learning_rate_at(state.epoch * batches + state.batch, total_steps);
            model = optim.step_multi(lr, model, grads);
            if session.kill_after == Some((state.epoch, state.batch)) {
                return Err(ModelError::Invalid("killed (test)".into()));
            }
            state.loss_sum += f64::from(value) * indices.len() as f64;
            state.samples += indices.len();
            state.batch += 1;
            let seconds = started.elapsed().as_secs_f64();
            state.epoch_seconds += seconds;
            state.total_seconds += seconds;
            progress.batch_done(indices.len(), &state);
            let epoch_done = state.batch == batches;
            if !epoch_done && last_checkpoint.elapsed().as_secs_f64() >= config.checkpoint_seconds {
                checkpoint::save(&checkpoint, &model, &optim, &state)?;
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
        // Every `checkpoint_seconds` and at the end (epochs of small networks take
        // milliseconds: a checkpoint after each would cost more than the epoch).
        let last = state.epoch == config.epochs;
        let out_of_time = !last && deadline.is_some_and(|d| Instant::now() >= d);
        if last
            || out_of_time
            || last_checkpoint.elapsed().as_secs_f64() >= config.checkpoint_seconds
        {
            checkpoint::save(&checkpoint, &model, &optim, &state)?;
            last_checkpoint = Instant::now();
        }
        write_log(&dir.join(LOG_FILE), &state.log)?;
        if out_of_time {
            session.progress.status(&format!(
                "{}: time limit reached after epoch {} of {}; resume continues from the \
                 checkpoint in {}",
                session.label,
                state.epoch,
                config.epochs,
                dir.display()
            ));
            break;
        }
    }
    progress.finish();
    Ok(Outcome { model, log: state.log, seconds: state.total_seconds })
}

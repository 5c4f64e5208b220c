//! Training of the autoencoder (§3.2) through the shared loop ([`crate::train::run`]): Adam on
//! the masked L2 loss of eq. (4), seeded shuffling, slice dropout, checkpoints that resume
//! exactly, and the final per-BRDF evaluation.

pub(crate) mod batch;
pub(crate) mod config;

use std::path::Path;
use std::time::Duration;

use burn::prelude::*;
use deepbrdf_data::Progress;

pub use config::{saved_config, SliceDropoutConfig, TrainConfig};

use crate::autoencoder::convolutional::step::ConvolutionalStep;
use crate::autoencoder::slice::step::SliceStep;
use crate::autoencoder::{
    retired_message, retired_network, Architecture, Autoencoder, INPUT_VALUES,
};
use crate::error::ModelError;
use crate::train::checkpoint::{self, checkpoint_path};
use crate::train::log::EpochRecord;
use crate::train::run::{run, Session};
use crate::training_set::TrainingSet;
use batch::batch_tensors;
use deepbrdf_data::layout::PLANE;

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
    train_within(config, data, out_dir, resume, None, progress, device)
}

/// [`train`], stopping at the end of the first epoch that ends `time_limit` after the start
/// (with a checkpoint that `resume` continues; [`Session::with_time_limit`]): the network
/// returned then has the epochs done so far ([`Trained::log`]).
pub fn train_within(
    config: &TrainConfig,
    data: &TrainingSet,
    out_dir: &Path,
    resume: bool,
    time_limit: Option<Duration>,
    progress: &dyn Progress,
    device: &Device,
) -> crate::error::Result<Trained> {
    let session =
        Session::new(out_dir, resume, progress, &label(config)).with_time_limit(time_limit);
    train_in(config, data, &session, device)
}

fn label(config: &TrainConfig) -> String {
    format!("training k={}", config.model.latent)
}

/// [`train`] in `session`.
fn train_in(
    config: &TrainConfig,
    data: &TrainingSet,
    session: &Session<'_>,
    device: &Device,
) -> crate::error::Result<Trained> {
    config.validate()?;
    let identity = serde_json::to_value(config)
        .map_err(|e| ModelError::Invalid(format!("cannot serialise the configuration: {e}")))?;
    let path = checkpoint_path(session.dir());
    if path.exists() && session.resumes() {
        let saved = checkpoint::saved_run_config(&path)?;
        if let Some(what) = saved.get("model").and_then(retired_network) {
            return Err(ModelError::format(&path, retired_message(what)));
        }
    }
    let fingerprint = data.fingerprint();
    let settings = config.loop_config();
    // Each network family brings its own step to the one loop.
    let outcome = match &config.model.architecture {
        Architecture::Convolutional(_) => {
            let mut step = ConvolutionalStep::new(config, data)?;
            run(&settings, &identity, &fingerprint, data.len(), &mut step, session, device)?
        }
        Architecture::Slice(layers) => {
            let mut step = SliceStep::new(config, layers, data)?;
            let samples = step.samples();
            run(&settings, &identity, &fingerprint, samples, &mut step, session, device)?
        }
    };
    let model = outcome.model.valid();
    let per_material_mse = evaluate(&model, data, config.batch_size, session.progress())?;
    Ok(Trained {
        model,
        config: config.clone(),
        log: outcome.log,
        seconds: outcome.seconds,
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

        // Summed over one image of the layout on the device, the 540 images of a BRDF in f64
        // here: one reduction over all 4.4 M values of a BRDF returned 18-56x too little on
        // wgpu (Mesa's lavapipe), and f32 accumulation over millions of values loses digits.
        let planes = INPUT_VALUES / PLANE;
        let sq = (diff.clone() * diff).reshape([batch * planes, PLANE]).sum_dim(1); // [batch * 540, 1]
        let sq = crate::read_back::values(sq, "the squared errors")?;
        for (per_plane, v) in sq.chunks(planes).zip(&b.valid) {
            let total: f64 = per_plane.iter().map(|&s| f64::from(s)).sum();
            errors.push(total / v.max(1.0));
        }
        progress.advance(batch as u64);
    }
    progress.finish();
    Ok(errors)
}

#[cfg(test)]
mod tests;

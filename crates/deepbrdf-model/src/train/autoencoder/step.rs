//! The autoencoder's training step ([`TrainStep`]): its initialisation (seeded, around the
//! training mean), and the eq. (4) loss and gradients of a batch, on the full layouts
//! (convolutional networks, in parallel shards) or on the slice coefficients (slice networks).

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use deepbrdf_data::augment::SliceSelection;
use deepbrdf_data::Progress;

use super::batch::{batch_tensors, Augment, Batch};
use super::config::TrainConfig;
use super::slice_step::{self, SliceFit};
use crate::autoencoder::Autoencoder;
use crate::loss::masked_mse_centred;
use crate::train::run::TrainStep;
use crate::training_set::TrainingSet;

/// The autoencoder of `config` trained on `data`.
pub(crate) struct AutoencoderStep<'a> {
    config: &'a TrainConfig,
    data: &'a TrainingSet,
    /// Slice dropout: its probability and selections.
    dropout: Option<(f64, Vec<SliceSelection>)>,
    /// The fixed offset, for centring batches on the CPU (see [`Batch`]).
    offset: Option<Vec<f32>>,
    /// A slice network's coefficients of the training samples.
    slice: Option<SliceFit>,
}

impl<'a> AutoencoderStep<'a> {
    pub(crate) fn new(
        config: &'a TrainConfig,
        data: &'a TrainingSet,
    ) -> crate::error::Result<Self> {
        let dropout = match &config.slice_dropout {
            Some(d) => Some((d.probability, d.parsed()?)),
            None => None,
        };
        Ok(Self { config, data, dropout, offset: None, slice: None })
    }

    /// The number of training samples: the BRDFs, and the augmentations of a slice network.
    pub(crate) fn samples(&self) -> usize {
        match self.config.model.slice_config() {
            Some(layers) => layers.augmentation.samples(self.data.len()),
            None => self.data.len(),
        }
    }
}

impl TrainStep for AutoencoderStep<'_> {
    type Model = Autoencoder;

    fn init(&mut self, device: &Device) -> crate::error::Result<Autoencoder> {
        let model = self.skeleton(device)?;
        match self.config.model.mean_offset() {
            true => model.with_offset(&self.data.mean()),
            false => Ok(model),
        }
    }

    fn skeleton(&mut self, device: &Device) -> crate::error::Result<Autoencoder> {
        // Seeded too: an unseeded draw from the shared generator could fall between the
        // seeding and the draws of another run's initialisation.
        self.config.model.init_seeded(self.config.seed, device)
    }

    /// Fits a slice network's fixed parts to the training set (again on resume: the fit is
    /// deterministic).
    fn prepare(
        &mut self,
        model: Autoencoder,
        fresh: bool,
        progress: &dyn Progress,
    ) -> crate::error::Result<Autoencoder> {
        self.offset = model.offset();
        if let Some(layers) = self.config.model.slice_config() {
            let selections = self.dropout.as_ref().map(|(_, s)| s.as_slice());
            let (model, fit) = slice_step::prepare(
                model,
                self.data,
                layers,
                selections,
                self.config.seed,
                fresh,
                progress,
            )?;
            self.slice = Some(fit);
            return Ok(model);
        }
        Ok(model)
    }

    fn step(
        &mut self,
        model: &Autoencoder,
        epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> crate::error::Result<(f32, MultiGradientsParams)> {
        let augment = self.dropout.as_ref().map(|(p, selections)| Augment {
            probability: *p,
            selections,
            seed: self.config.seed,
            epoch,
        });
        if let Some(fit) = &self.slice {
            let n = self.data.len();
            let inputs: Vec<f32> = indices
                .iter()
                .flat_map(|&i| {
                    let choice = augment.as_ref().filter(|_| i < n).and_then(|a| a.choice(i));
                    match (&fit.filled, choice) {
                        (Some(filled), Some(s)) => filled[i][s].clone(),
                        _ => fit.target(i).to_vec(),
                    }
                })
                .collect();
            return slice_step::slice_gradients(model, fit, indices, inputs, device);
        }
        Ok(gradients(
            model,
            self.data,
            indices,
            augment.as_ref(),
            self.offset.as_deref(),
            self.config.threads,
            device,
        ))
    }
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

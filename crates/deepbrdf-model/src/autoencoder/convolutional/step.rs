//! The convolutional network's training step ([`TrainStep`]): its initialisation (seeded,
//! around the training mean when it has an offset, scaled by the training spread when it
//! standardises) and the eq. (4) loss and gradients of a
//! batch on the full layouts, computed in parallel shards.

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;

use crate::autoencoder::train::batch::{batch_tensors, Augment, Batch, SliceDropout};
use crate::autoencoder::train::config::TrainConfig;
use crate::autoencoder::Autoencoder;
use crate::loss::{masked_error_centred, LossNorm};
use crate::train::run::TrainStep;
use crate::training_set::TrainingSet;

/// Table 1's network (or a narrower variant) of `config` trained on `data`.
pub(crate) struct ConvolutionalStep<'a> {
    config: &'a TrainConfig,
    data: &'a TrainingSet,
    dropout: Option<SliceDropout>,
    /// The fixed offset, for centring batches on the CPU (see [`Batch`]).
    offset: Option<Vec<f32>>,
}

impl<'a> ConvolutionalStep<'a> {
    pub(crate) fn new(
        config: &'a TrainConfig,
        data: &'a TrainingSet,
    ) -> crate::error::Result<Self> {
        if let Some(streamed) = data.streamed() {
            return Err(crate::error::ModelError::Invalid(format!(
                "{}: streamed BRDFs train the slice network only (the convolutional network \
                 reads whole layouts every epoch)",
                streamed.label()
            )));
        }
        Ok(Self { config, data, dropout: config.dropout()?, offset: None })
    }
}

impl TrainStep for ConvolutionalStep<'_> {
    type Model = Autoencoder;

    fn init(&mut self, device: &Device) -> crate::error::Result<Autoencoder> {
        let model = self.skeleton(device)?;
        let model = match self.config.model.mean_offset() {
            true => model.with_offset(&self.data.mean())?,
            false => model,
        };
        match self.config.model.standardise() {
            true => model.with_scale(&self.data.spread()),
            false => Ok(model),
        }
    }

    fn skeleton(&mut self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.config.init_network(device)
    }

    fn prepare(
        &mut self,
        model: Autoencoder,
        _fresh: bool,
        _progress: &dyn deepbrdf_data::Progress,
    ) -> crate::error::Result<Autoencoder> {
        self.offset = model.offset();
        Ok(model)
    }

    fn step(
        &mut self,
        model: &Autoencoder,
        epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> crate::error::Result<(f32, MultiGradientsParams)> {
        let augment = self.dropout.as_ref().map(|d| d.at_epoch(epoch));
        Ok(gradients(
            model,
            self.data,
            indices,
            augment.as_ref(),
            self.offset.as_deref(),
            self.config.threads,
            self.config.norm(),
            device,
        ))
    }
}

/// The eq. (4) loss of a batch under `norm`, its error divided by `valid` (the valid values of
/// the whole batch when this is a shard of it): the forward step training and benchmarks share.
pub(crate) fn batch_loss(
    model: &Autoencoder,
    batch: Batch,
    valid: f64,
    norm: LossNorm,
) -> Tensor<1> {
    let deviation = model.decode_deviation(model.encode_centred(batch.input)); // [batch, 540, 90, 90]
    masked_error_centred(deviation, batch.target, batch.mask, valid, norm) // [1]
}

/// The loss and gradients of the batch `indices`, computed in `threads` shards in parallel
/// (Burn's CPU backends as built here run each operation on one core; shards put both cores
/// to work). Each shard works on its own fork of the model (its own autodiff graph); the
/// optimizer sums the shards' gradients, each normalised by the whole batch's valid values,
/// so the step is that of the whole batch. Deterministic for a given `threads`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn gradients(
    model: &Autoencoder,
    data: &TrainingSet,
    indices: &[usize],
    augment: Option<&Augment>,
    offset: Option<&[f32]>,
    threads: usize,
    norm: LossNorm,
    device: &Device,
) -> (f32, MultiGradientsParams) {
    let valid: f64 = indices.iter().map(|&i| data.valid_values(i)).sum();
    let shard = |indices: &[usize], forked: bool| {
        let model = if forked { model.clone().fork(device) } else { model.clone() };
        let batch = batch_tensors(data, indices, augment, offset, device);
        let loss = batch_loss(&model, batch, valid, norm);
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

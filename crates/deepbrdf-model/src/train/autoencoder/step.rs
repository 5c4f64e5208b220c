//! The autoencoder's training step ([`TrainStep`]): its initialisation (seeded, around the
//! training mean), the basis fit of a spectral network, and the eq. (4) loss and gradients of a
//! batch, on the full layouts (convolutional networks, in parallel shards) or on the spectral
//! coordinates (spectral networks, see [`crate::spectral`]).

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::augment::SliceSelection;
use deepbrdf_data::Progress;

use super::batch::{batch_tensors, filled_coefficients, Augment, Batch};
use super::config::TrainConfig;
use super::slice_step::{self, SliceFit};
use crate::autoencoder::Autoencoder;
use crate::error::ModelError;
use crate::loss::masked_mse_centred;
use crate::principal::PrincipalFit;
use crate::spectral::SpectralPath;
use crate::train::run::{on_device, TrainStep};
use crate::training_set::TrainingSet;

/// The autoencoder of `config` trained on `data`.
pub(crate) struct AutoencoderStep<'a> {
    config: &'a TrainConfig,
    data: &'a TrainingSet,
    /// Slice dropout: its probability and selections.
    dropout: Option<(f64, Vec<SliceSelection>)>,
    /// The fixed offset, for centring batches on the CPU (see [`Batch`]).
    offset: Option<Vec<f32>>,
    /// A spectral network's fit of the training set (coordinates and residuals; the basis is
    /// in the network).
    fit: Option<PrincipalFit>,
    /// With slice dropout on coordinates: the coordinates of the filled inputs,
    /// `[brdf][selection][K]`, computed once.
    dropout_coefficients: Option<Vec<Vec<Vec<f32>>>>,
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
        Ok(Self {
            config,
            data,
            dropout,
            offset: None,
            fit: None,
            dropout_coefficients: None,
            slice: None,
        })
    }

    /// Whether `prepare` fits the basis of a spectral network around the training mean (and
    /// sets it: the network is built without one).
    fn fits_basis(&self) -> bool {
        self.config.model.spectral_config().is_some()
            && self.config.model.mean_offset()
            && self.config.model.slice_config().is_none()
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
        // seeding and the draws of another run's initialisation. A fitted basis is not built
        // (no zero basis in the meantime: no random draw makes it).
        match self.fits_basis() {
            true => self.config.model.init_seeded_without_basis(self.config.seed, device),
            false => self.config.model.init_seeded(self.config.seed, device),
        }
    }

    /// Checkpoints leave out a fitted basis (1.7 GB for the `cpu` preset): resuming fits it
    /// again, to the same bits (the fit is deterministic and the data are checked).
    fn checkpointed(&self, model: &Autoencoder) -> Autoencoder {
        match self.fits_basis() {
            true => model.clone().without_basis(),
            false => model.clone(),
        }
    }

    /// Fits a spectral network's basis to the training set (again on resume: the fit is
    /// deterministic), sets it in a new network, and projects the slice-dropout inputs.
    fn prepare(
        &mut self,
        model: Autoencoder,
        fresh: bool,
        progress: &dyn Progress,
    ) -> crate::error::Result<Autoencoder> {
        let mut model = model;
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
        let (Some(spectral), Some(mean)) = (self.config.model.spectral_config(), &self.offset)
        else {
            return Ok(model);
        };
        progress.status(&format!("fitting {} principal directions", spectral.directions));
        let mut fit = crate::principal::fit_basis(self.data, mean, spectral.directions)?;
        // Moved into the network (a resumed one has none: checkpoints leave it out; one
        // saved with its basis keeps it, the same values); only the coordinates are needed.
        let basis = std::mem::take(&mut fit.basis);
        if fresh || !model.spectral().is_some_and(SpectralPath::has_basis) {
            model = model.with_basis(basis)?;
        }
        self.fit = Some(fit);
        if let Some((_, selections)) = &self.dropout {
            progress.status("projecting the slice-dropout inputs");
            self.dropout_coefficients =
                Some(filled_coefficients(&model, self.data, mean, selections, self.config.seed)?);
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
        match &self.fit {
            Some(fit) => {
                let inputs: Vec<f32> = indices
                    .iter()
                    .flat_map(|&i| {
                        let choice = augment.as_ref().and_then(|a| a.choice(i));
                        match (&self.dropout_coefficients, choice) {
                            (Some(filled), Some(s)) => filled[i][s].clone(),
                            _ => fit.coefficients[i].clone(),
                        }
                    })
                    .collect();
                coefficient_gradients(model, self.data, fit, indices, inputs, device)
            }
            None => Ok(gradients(
                model,
                self.data,
                indices,
                augment.as_ref(),
                self.offset.as_deref(),
                self.config.threads,
                device,
            )),
        }
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

/// The eq. (4) loss of the batch `indices` and its gradients, computed on the spectral
/// coordinates of a network without convolutions: for orthonormal basis rows, the squared error
/// of a training BRDF is `|c_hat - c|^2` plus its (fixed) distance to the basis' span.
pub(crate) fn coefficient_gradients(
    model: &Autoencoder,
    data: &TrainingSet,
    fit: &PrincipalFit,
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
    Ok((value, on_device(GradientsParams::from_grads(loss.backward(), model), device)))
}

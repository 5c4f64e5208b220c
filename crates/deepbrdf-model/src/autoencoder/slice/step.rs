//! The `slice` network's training step ([`TrainStep`], [`super::network`]): the fits of its
//! fixed parts (slice basis, mean and principal components of the coefficients of the training
//! BRDFs and their augmentations) and the eq. (4) loss of a batch on coefficients.
//!
//! For an orthonormal slice basis B, the squared error of an output `B^T a_hat` against a
//! training layout x is `|a_hat - B x|^2` plus the (fixed) squared distance of x to B's span:
//! training runs on the 540 x M coefficients of each BRDF, computed once. With cell weights
//! ([`super::basis::pixel_weights`]) the same holds for the weighted error: eq. (4) with each
//! cell counted by its weight, more at the highlight's centre. (The output is compared on every cell of each image; the masked
//! loss of eq. (4) skips the cells invalid in that slice, where the target's projection is
//! near 0: the coefficient loss bounds it from above.)

use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::augment::SliceSelection;
use deepbrdf_data::Progress;

use deepbrdf_data::layout::LAYOUT_VALUES;

use super::augmentation::sample_layout;
use super::basis::{basis_t, fit_slice_basis, fit_weighted_components, pixel_weights, project};
use super::config::SliceConfig;
use crate::autoencoder::train::batch::{centre, filled_input, SliceDropout};
use crate::autoencoder::train::config::TrainConfig;
use crate::autoencoder::Autoencoder;
use crate::error::ModelError;
use crate::loss::{colour_weights, LossNorm};
use crate::streamed::mapped_layout;
use crate::train::run::{on_device, TrainStep};
use crate::training_set::TrainingSet;

/// Samples projected with one product.
const PROJECTED_AT_ONCE: usize = 8;

/// The slice network of `config` (its settings `layers`) trained on `data` and the
/// augmentations of it.
pub(crate) struct SliceStep<'a> {
    config: &'a TrainConfig,
    layers: &'a SliceConfig,
    data: &'a TrainingSet,
    dropout: Option<SliceDropout>,
    /// The coefficients of the training samples, once [`prepare`](TrainStep::prepare)d.
    fit: Option<SliceFit>,
}

impl<'a> SliceStep<'a> {
    pub(crate) fn new(
        config: &'a TrainConfig,
        layers: &'a SliceConfig,
        data: &'a TrainingSet,
    ) -> crate::error::Result<Self> {
        Ok(Self { config, layers, data, dropout: config.dropout()?, fit: None })
    }

    /// The number of examples of an epoch: the held samples (the BRDFs and their
    /// augmentations) `held_passes` times, then the streamed BRDFs once.
    pub(crate) fn samples(&self) -> usize {
        self.held() * self.layers.augmentation.held_passes
            + self.data.streamed().map_or(0, |s| s.len())
    }

    /// The number of held samples.
    fn held(&self) -> usize {
        self.layers.augmentation.samples(self.data.len())
    }

    /// The sample of example `i` of an epoch (see [`samples`](Self::samples)).
    fn sample_of(&self, i: usize) -> usize {
        let held = self.held();
        let passes = self.layers.augmentation.held_passes;
        match i < held * passes {
            true => i % held,
            false => i - held * (passes - 1),
        }
    }
}

impl TrainStep for SliceStep<'_> {
    type Model = Autoencoder;

    fn init(&mut self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.config.init_network(device)
    }

    /// Fits the network's fixed parts to the training set (again on resume: the fits are
    /// deterministic).
    fn prepare(
        &mut self,
        model: Autoencoder,
        fresh: bool,
        progress: &dyn Progress,
    ) -> crate::error::Result<Autoencoder> {
        let selections = self.dropout.as_ref().map(|d| d.selections.as_slice());
        let (model, fit) =
            prepare(model, self.data, self.layers, selections, self.config.seed, fresh, progress)?;
        self.fit = Some(fit);
        Ok(model)
    }

    fn step(
        &mut self,
        model: &Autoencoder,
        epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> crate::error::Result<(f32, MultiGradientsParams)> {
        let fit = self
            .fit
            .as_ref()
            .ok_or_else(|| ModelError::Invalid("a slice step before its fit".into()))?;
        let augment = self.dropout.as_ref().map(|d| d.at_epoch(epoch));
        let n = self.data.len();
        let indices: Vec<usize> = indices.iter().map(|&i| self.sample_of(i)).collect();
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
        slice_gradients(model, fit, &indices, inputs, self.config.norm(), device)
    }
}

/// The coefficients of every training sample (the BRDFs, then their augmentations).
struct SliceFit {
    /// `[sample][540 * M]`: the targets.
    targets: Vec<Vec<f32>>,
    /// Squared distance of each sample's layout to the slice basis' span.
    residuals: Vec<f64>,
    /// Valid values of each sample.
    valid: Vec<f64>,
    /// With the image-space weighting: each sample's colour-channel weights in the loss
    /// ([`colour_weights`], scaled to mean 1 over the samples and channels).
    weights: Option<Vec<[f32; 3]>>,
    /// With slice dropout: the coefficients of the filled inputs of the BRDFs (not of the
    /// augmentations), `[brdf][selection][540 * M]`.
    filled: Option<Vec<Vec<Vec<f32>>>>,
}

impl SliceFit {
    /// The target coefficients of sample `i`.
    fn target(&self, i: usize) -> &[f32] {
        &self.targets[i]
    }
}

/// Fits the slice basis to `data`, projects its BRDFs and their augmentations, fits the mean
/// and principal components of the coefficients and sets all three in `model` when `fresh`
/// (a resumed network has them from its checkpoint; the fits are deterministic).
fn prepare(
    model: Autoencoder,
    data: &TrainingSet,
    layers: &SliceConfig,
    selections: Option<&[SliceSelection]>,
    seed: u64,
    fresh: bool,
    progress: &dyn Progress,
) -> crate::error::Result<(Autoencoder, SliceFit)> {
    progress.status(&format!("fitting a slice basis of {} directions", layers.directions));
    let layouts: Vec<&[f32]> = (0..data.len()).map(|i| data.input(i)).collect();
    let device = model.devices().into_iter().next().unwrap_or_default().without_autodiff();
    let cell_weights = pixel_weights(layers.centre_emphasis.unwrap_or(0.0));
    let basis = fit_slice_basis(&layouts, layers.directions, &cell_weights, seed, &device)?;
    drop(layouts);
    let bt = basis_t(&basis, &cell_weights, &device);
    let augmentation = &layers.augmentation;
    let n = data.len();
    let samples = augmentation.samples(n);
    let (mut targets, mut residuals, mut valid) =
        (Vec::with_capacity(samples), Vec::with_capacity(samples), Vec::with_capacity(samples));
    let power = augmentation.image_weight_power;
    let reference = match power > 0.0 {
        true => Some(data.reference_layout().ok_or_else(|| {
            ModelError::Invalid(format!(
                "{}: the image-space weighting needs the eq. (1) reference of the set",
                data.label()
            ))
        })?),
        false => None,
    };
    let mut weights = Vec::with_capacity(if reference.is_some() { samples } else { 0 });
    progress.start(samples as u64, "projecting the training BRDFs and their augmentations");
    let indices: Vec<usize> = (0..samples).collect();
    for group in indices.chunks(PROJECTED_AT_ONCE) {
        let made = group
            .iter()
            .map(|&i| sample_layout(data, augmentation.sample(n, i, seed)))
            .collect::<crate::error::Result<Vec<_>>>()?;
        let layouts: Vec<&[f32]> = made.iter().map(|(l, _)| l.as_slice()).collect();
        if let Some(r) = reference {
            weights.extend(layouts.iter().map(|l| colour_weights(l, r, power)));
        }
        for ((a, r), (_, count)) in project(&layouts, &bt, &cell_weights)?.into_iter().zip(&made) {
            targets.push(a);
            residuals.push(r);
            valid.push(*count);
        }
        progress.advance(group.len() as u64);
    }
    progress.finish();
    if let Some(streamed) = data.streamed() {
        let reference = data.reference_layout().ok_or_else(|| {
            ModelError::Invalid(format!(
                "{}: streamed BRDFs need the set's reference",
                data.label()
            ))
        })?;
        let power = (power > 0.0).then_some(power);
        progress.start(streamed.len() as u64, "tabulating and projecting the streamed BRDFs");
        let mut group: Vec<(Vec<f32>, f64)> = Vec::with_capacity(PROJECTED_AT_ONCE);
        let mut flush = |group: &mut Vec<(Vec<f32>, f64)>| -> crate::error::Result<()> {
            let layouts: Vec<&[f32]> = group.iter().map(|(l, _)| l.as_slice()).collect();
            if let Some(p) = power {
                weights.extend(layouts.iter().map(|l| colour_weights(l, reference, p)));
            }
            for ((a, r), (_, count)) in
                project(&layouts, &bt, &cell_weights)?.into_iter().zip(group.iter())
            {
                targets.push(a);
                residuals.push(r);
                valid.push(*count);
            }
            group.clear();
            Ok(())
        };
        streamed.for_each(progress, |_, _, table| {
            group.push(mapped_layout(&table, reference)?);
            if group.len() == PROJECTED_AT_ONCE {
                flush(&mut group)?;
            }
            Ok(())
        })?;
        flush(&mut group)?;
        progress.finish();
    }
    let weights = reference.map(|_| normalised(weights));
    if let Some(weights) = &weights {
        let mut all: Vec<f32> = weights.iter().flatten().copied().collect();
        all.sort_by(f32::total_cmp);
        let at = |q: f64| all[((all.len() - 1) as f64 * q) as usize];
        progress.status(&format!(
            "image-space colour weights (power {power}): min {:.3}, median {:.3}, 90% {:.3}, max {:.3}",
            at(0.0),
            at(0.5),
            at(0.9),
            at(1.0)
        ));
    }
    progress.status(&format!("fitting {} principal components", layers.components));
    let passes = augmentation.held_passes as f64;
    let counts: Vec<f64> =
        (0..targets.len()).map(|i| if i < samples { passes } else { 1.0 }).collect();
    let components = fit_weighted_components(&targets, &counts, layers.components)?;
    let mut model = model;
    if fresh {
        model = model.with_slice_fit(&basis, &components.mean, &components.rows)?;
    }
    let filled = match selections {
        Some(selections) => {
            progress.status("projecting the slice-dropout inputs");
            let mut row = vec![0f32; LAYOUT_VALUES];
            let filled = (0..n)
                .map(|i| {
                    selections
                        .iter()
                        .enumerate()
                        .map(|(s, selection)| {
                            let input = filled_input(data, i, s, selection, seed);
                            centre(&mut row, &input, data.mask(i), None);
                            Ok(project(&[&row], &bt, &cell_weights)?.remove(0).0)
                        })
                        .collect::<crate::error::Result<Vec<_>>>()
                })
                .collect::<crate::error::Result<Vec<_>>>()?;
            Some(filled)
        }
        None => None,
    };
    Ok((model, SliceFit { targets, residuals, valid, weights, filled }))
}

/// `weights` scaled to mean 1 over all samples and channels.
fn normalised(weights: Vec<[f64; 3]>) -> Vec<[f32; 3]> {
    let count = (3 * weights.len()).max(1) as f64;
    let mean = weights.iter().flatten().sum::<f64>() / count;
    let scale = if mean.is_finite() && mean > 0.0 { 1.0 / mean } else { 1.0 };
    weights.iter().map(|w| w.map(|v| (v * scale) as f32)).collect()
}

/// The eq. (4) loss of the samples `indices` (their coefficients' error under `norm`, each
/// colour channel's times its weight, over their valid values; with L2 plus their residuals)
/// and its gradients; `inputs` are the encoder's input coefficients, the targets' or those of
/// filled inputs.
///
/// The basis is orthonormal, so the coefficients' L2 error is the cells' (plus the residual, a
/// constant); their L1 error is not the cells' L1 error, but it is the same change of norm
/// acting on the same network, which is what Fig. 4 compares.
fn slice_gradients(
    model: &Autoencoder,
    fit: &SliceFit,
    indices: &[usize],
    inputs: Vec<f32>,
    norm: LossNorm,
    device: &Device,
) -> crate::error::Result<(f32, MultiGradientsParams)> {
    let net = model
        .slice()
        .ok_or_else(|| ModelError::Invalid("slice training needs a slice network".into()))?;
    let len = net.coefficient_len();
    let valid: f64 = indices.iter().map(|&i| fit.valid[i]).sum();
    let residual: f64 = indices.iter().map(|&i| fit.residuals[i]).sum();
    let targets: Vec<f32> = indices.iter().flat_map(|&i| fit.targets[i].clone()).collect();
    let b = indices.len();
    let target = Tensor::<2>::from_data(TensorData::new(targets, [b, len]), device);
    let input = Tensor::<2>::from_data(TensorData::new(inputs, [b, len]), device);
    let diff = net.decode_coefficients(net.encode_coefficients(input)) - target; // [batch, 540 M]
    let error = norm.error(diff); // [batch, 540 M]
    let error = match &fit.weights {
        Some(weights) => {
            let m = net.directions();
            let values: Vec<f32> = indices
                .iter()
                .flat_map(|&i| {
                    let w = weights[i];
                    (0..len).map(move |j| w[(j / m) % 3]) // coefficient j: image j / M
                })
                .collect();
            error * Tensor::<2>::from_data(TensorData::new(values, [b, len]), device)
        }
        None => error,
    };
    let loss = error.sum().div_scalar(valid.max(1.0)); // [1]
    let value: f32 = loss.clone().into_scalar();
    let value = match norm {
        LossNorm::L2 => value + (residual / valid.max(1.0)) as f32,
        LossNorm::L1 => value,
    };
    Ok((value, on_device(GradientsParams::from_grads(loss.backward(), model), device)))
}

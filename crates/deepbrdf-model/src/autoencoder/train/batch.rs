//! One batch of the autoencoder's training data, prepared on the CPU: inputs and targets
//! centred on the fixed offset and masked, and slice dropout (§3.2, Fig. 2) drawn per (seed,
//! epoch, BRDF), shared by the network families' training steps.

use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::augment::{fill_missing_layout, kept_slices, SliceSelection};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::training_set::TrainingSet;
use deepbrdf_data::layout::{
    LAYOUT_VALUES as INPUT_VALUES, SIDE as INPUT_SIDE, SLICE_CHANNELS as INPUT_CHANNELS,
};

/// Slice dropout of a run: its probability, its parsed selections and the run's seed.
pub(crate) struct SliceDropout {
    pub probability: f64,
    pub selections: Vec<SliceSelection>,
    pub seed: u64,
}

impl SliceDropout {
    /// The dropout of epoch `epoch` (0-based).
    pub(crate) fn at_epoch(&self, epoch: usize) -> Augment<'_> {
        Augment {
            probability: self.probability,
            selections: &self.selections,
            seed: self.seed,
            epoch,
        }
    }
}

/// Slice dropout applied to one batch.
pub(crate) struct Augment<'a> {
    pub probability: f64,
    pub selections: &'a [SliceSelection],
    pub seed: u64,
    pub epoch: usize,
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
    pub(crate) fn choice(&self, index: usize) -> Option<usize> {
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
/// [`crate::loss::masked_error_centred`] expects.
pub(crate) struct Batch {
    /// `[batch, 540, 90, 90]`: the network's input (with slice dropout, the filled one).
    pub input: Tensor<4>,
    /// `[batch, 540, 90, 90]`: the centred, masked target.
    pub target: Tensor<4>,
    /// `[batch, 540, 90, 90]`
    pub mask: Tensor<4>,
    /// Valid values of each BRDF.
    pub valid: Vec<f64>,
}

/// BRDF `i` of `data` with only the slices of `selection` (number `s` of the run's selections),
/// each missing slice filled from its nearest kept one; the kept slices of a random selection
/// are drawn once per (seed, BRDF, selection). Not masked.
pub(crate) fn filled_input(
    data: &TrainingSet,
    i: usize,
    s: usize,
    selection: &SliceSelection,
    seed: u64,
) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xf111_ed5e_u64);
    rng.set_stream(((i as u64) << 16) | s as u64);
    let mut filled = data.input(i).to_vec();
    fill_missing_layout(&mut filled, &kept_slices(selection, rng.random()));
    filled
}

/// Writes `(x - offset) * mask` into `out`, in parallel.
pub(crate) fn centre(out: &mut [f32], x: &[f32], mask: &[f32], offset: Option<&[f32]>) {
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

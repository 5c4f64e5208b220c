//! Speed measurements of the networks, for `experiments bench model`: seconds per training step
//! (forward, eq. (4) loss, backward, Adam) and seconds to decode a latent vector into a full
//! MERL table (through the codec, [`DeepBrdf`]). Inputs are synthetic (random mapped values on
//! the MERL grid's mask): speed does not depend on the values.

use std::time::Instant;

use burn::prelude::*;
use deepbrdf_data::layout::mask_layout;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::merl::VALUES;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::autoencoder::artifact::{ModelArtifact, Provenance};
use crate::autoencoder::convolutional::step::gradients;
use crate::autoencoder::AutoencoderConfig;
use crate::codec::DeepBrdf;
use crate::error::{ModelError, Result};
use crate::loss::LossNorm;
use crate::training_set::TrainingSet;
use deepbrdf_data::merl::grid::valid_mask;

/// Median and all timings of repeated runs, in seconds.
#[derive(Debug, Clone)]
pub struct Timing {
    /// Every measured run (the warm-up excluded).
    pub runs: Vec<f64>,
}

impl Timing {
    /// The median run.
    pub fn median(&self) -> f64 {
        let mut v = self.runs.clone();
        v.sort_by(f64::total_cmp);
        if v.is_empty() {
            return f64::NAN;
        }
        v[v.len() / 2]
    }
}

/// Times `steps` training steps (after one warm-up step) on batches of `batch` BRDFs, exactly
/// as a convolutional network's training runs them: batch preparation on the CPU, forward,
/// eq. (4) loss, backward, Adam (a slice network's fixed parts are left at zero: speed does not
/// depend on their values).
pub fn training_steps(
    config: &AutoencoderConfig,
    batch: usize,
    threads: usize,
    steps: usize,
    device: &Device,
) -> Result<Timing> {
    if batch == 0 || steps == 0 || batch > 256 {
        return Err(ModelError::Invalid("need 1 to 256 BRDFs and at least one step".into()));
    }
    let device = device.clone().autodiff();
    let set = synthetic_set(batch)?;
    let mut model = config.init_seeded(0, &device)?;
    if config.mean_offset() {
        model = model.with_offset(&set.mean())?;
    }
    let offset = model.offset();
    let mut optim = crate::train::adam().init();
    let indices: Vec<usize> = (0..batch).collect();
    let mut runs = Vec::with_capacity(steps);
    for step in 0..=steps {
        let start = Instant::now();
        let (value, grads) = gradients(
            &model,
            &set,
            &indices,
            None,
            offset.as_deref(),
            threads,
            LossNorm::L2,
            &device,
        );
        model = optim.step_multi(1e-5, model, grads);
        device.sync().map_err(|e| ModelError::Invalid(format!("device error: {e:?}")))?;
        if !value.is_finite() {
            return Err(ModelError::Invalid("the benchmark's loss is not finite".into()));
        }
        if step > 0 {
            runs.push(start.elapsed().as_secs_f64());
        }
    }
    Ok(Timing { runs })
}

/// `n` BRDFs of seeded random mapped values on the MERL grid's mask.
fn synthetic_set(n: usize) -> Result<TrainingSet> {
    let mask = mask_layout(valid_mask());
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let inputs =
        (0..n).map(|_| mask.iter().map(|&m| m * rng.random_range(0.0..2.0f32)).collect()).collect();
    let names = (0..n).map(|i| format!("random-{i}")).collect();
    TrainingSet::from_layouts("random", names, inputs, vec![mask; n])
}

/// Decode timings, medians over repeated runs.
#[derive(Debug, Clone)]
pub struct DecodeTiming {
    /// The codec's network part: latent to the mapped 540 x 90 x 90 layout.
    pub network: Timing,
    /// The whole decode: network, inverse layout, inverse eq. (1) on the grid's valid cells.
    pub whole: Timing,
}

/// Times decoding one latent vector into a full MERL table through [`DeepBrdf`], as `decode`
/// and the evaluation use it, over `repeats` runs after one warm-up. A network with an offset
/// gets one of seeded random values on the grid's valid cells (speed does not depend on them).
pub fn decode(config: &AutoencoderConfig, repeats: usize, device: &Device) -> Result<DecodeTiming> {
    let device = device.clone().without_autodiff();
    let mut model = config.init_seeded(0, &device)?;
    let valid = mask_layout(valid_mask());
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    if config.mean_offset() {
        let offset: Vec<f32> = valid.iter().map(|&m| m * rng.random_range(-1.0..1.0f32)).collect();
        model = model.with_offset(&offset)?;
    }
    let latent: Vec<f32> = (0..config.latent).map(|i| 0.1 * (i as f32 - 2.0)).collect();
    let provenance = Provenance::untrained("benchmark", 0);
    let reference = MedianReference::from_values(vec![0.05; VALUES])?;
    let artifact = ModelArtifact::new(config.clone(), provenance, &model, reference)?;
    drop(model);
    let codec = DeepBrdf::from_artifact(artifact, &device)?;
    let network = timed(repeats, || codec.decode_layout(&latent))?;
    let whole = timed(repeats, || codec.decode(&latent))?;
    Ok(DecodeTiming { network, whole })
}

/// Times `repeats` runs of `f` (at least one) after one untimed warm-up.
pub fn timed<T, E>(
    repeats: usize,
    mut f: impl FnMut() -> std::result::Result<T, E>,
) -> std::result::Result<Timing, E> {
    std::hint::black_box(f()?);
    let mut runs = Vec::with_capacity(repeats.max(1));
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        std::hint::black_box(f()?);
        runs.push(start.elapsed().as_secs_f64());
    }
    Ok(Timing { runs })
}

//! Training-set augmentation in linear BRDF space (not in the paper): extra training
//! BRDFs made from the mapped layouts of a [`TrainingSet`] through the inverse of eq. (1) and
//! back, with the set's reference.
//!
//! - RGB channel permutations (the Neural-BRDF autoencoder's augmentation): each BRDF also in
//!   the 5 other orders of its colour channels, `rho'_c = rho_pi(c)`.
//! - Pairwise interpolation (AugMERL, NeuMaDiff): `rho = t rho_a + (1 - t) rho_b` for pairs
//!   (a, b) and weights t in [1/4, 3/4] drawn from the seed, valid where both are.
//! - Darker or lighter diffuse floors: `rho'_c = max(rho_c - (1 - s) d_c, 0)` for a BRDF and
//!   channel order drawn from the seed, `d_c` its channel's diffuse floor (the
//!   [`FLOOR_QUANTILE`] quantile of its valid values) and `s` log-uniform in [`FLOOR_SCALES`]:
//!   a Lambertian BRDF is scaled by `s`, a highlight keeps its height above the floor (dark
//!   dielectrics such as black-obsidian are bright specular lobes on a near-black floor).
//!
//! Sample `i < n` is BRDF i itself; the permutations follow (5 per BRDF), then the mixtures,
//! then the floor-scaled BRDFs.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::ModelError;
use crate::training_set::TrainingSet;
use deepbrdf_data::layout::{LAYOUT_VALUES, PLANE};
use deepbrdf_data::mapping::{inverse_log_relative, log_relative};
use deepbrdf_data::merl::N_PHI_D;

/// The orders of the three colour channels; the first is the identity.
const PERMUTATIONS: [[usize; 3]; 6] =
    [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
/// The quantile of a channel's valid linear values taken as its diffuse floor.
pub const FLOOR_QUANTILE: f64 = 0.1;
/// The range of a floor's scale `s` (drawn log-uniformly).
pub const FLOOR_SCALES: (f64, f64) = (1.0 / 16.0, 1.5);

/// Which extra BRDFs a training set is augmented with, and how its samples weigh in the loss.
/// Every field has a default (none; one pass), so a configuration written before a field
/// existed still loads, and one that leaves `held_passes` at 1 is written as before.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AugmentationConfig {
    /// Add every BRDF in the 5 other orders of its colour channels.
    pub rgb_permutations: bool,
    /// Pairwise mixtures in linear BRDF space per training BRDF (rounded down; 0: none).
    pub mixtures_per_brdf: f64,
    /// BRDFs with a scaled diffuse floor per training BRDF (rounded down; 0: none).
    pub floors_per_brdf: f64,
    /// P of the image-space weighting of each sample's colour channels in the training loss
    /// ([`crate::loss::colour_weights`]; 0: eq. (4)'s unweighted error).
    pub image_weight_power: f64,
    /// Passes over the held samples (the set's BRDFs and their augmentations) per epoch, against
    /// one over the streamed BRDFs; the held samples weigh as much in the fit of the principal
    /// components. A generated corpus streamed beside a few measured BRDFs otherwise outweighs
    /// them in the loss and in the components.
    #[serde(skip_serializing_if = "is_one")]
    pub held_passes: usize,
}

fn is_one(passes: &usize) -> bool {
    *passes == 1
}

impl Default for AugmentationConfig {
    fn default() -> Self {
        Self {
            rgb_permutations: false,
            mixtures_per_brdf: 0.0,
            floors_per_brdf: 0.0,
            image_weight_power: 0.0,
            held_passes: 1,
        }
    }
}

/// One augmented sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// A training BRDF as it is.
    Original(usize),
    /// BRDF `index` with its channels in order `PERMUTATIONS[order]`.
    Permuted { index: usize, order: usize },
    /// `t a + (1 - t) b`.
    Mixture { a: usize, b: usize, t: f64 },
    /// BRDF `index` with its channels in order `PERMUTATIONS[order]` and its diffuse floor
    /// scaled by `scale`.
    Floor { index: usize, order: usize, scale: f64 },
}

impl AugmentationConfig {
    /// No augmentation.
    pub fn new() -> Self {
        Self::default()
    }

    /// With or without the channel permutations.
    pub fn with_rgb_permutations(self, rgb_permutations: bool) -> Self {
        Self { rgb_permutations, ..self }
    }

    /// With this many mixtures per BRDF.
    pub fn with_mixtures_per_brdf(self, mixtures_per_brdf: f64) -> Self {
        Self { mixtures_per_brdf, ..self }
    }

    /// With this many floor-scaled BRDFs per BRDF.
    pub fn with_floors_per_brdf(self, floors_per_brdf: f64) -> Self {
        Self { floors_per_brdf, ..self }
    }

    /// With the image-space weighting of power `image_weight_power`.
    pub fn with_image_weight_power(self, image_weight_power: f64) -> Self {
        Self { image_weight_power, ..self }
    }

    /// With this many passes over the held samples per epoch.
    pub fn with_held_passes(self, held_passes: usize) -> Self {
        Self { held_passes, ..self }
    }

    /// The `slice` preset's: permutations and 4 mixtures per BRDF.
    pub fn preset() -> Self {
        Self::new().with_rgb_permutations(true).with_mixtures_per_brdf(4.0)
    }

    /// Checks the settings.
    pub fn validate(&self) -> crate::error::Result<()> {
        for (what, count) in
            [("mixtures", self.mixtures_per_brdf), ("floor-scaled BRDFs", self.floors_per_brdf)]
        {
            if !(0.0..=100.0).contains(&count) {
                return Err(ModelError::Invalid(format!(
                    "{count} {what} per BRDF is out of range (0 to 100)"
                )));
            }
        }
        if !(1..=100).contains(&self.held_passes) {
            return Err(ModelError::Invalid(format!(
                "{} passes over the held samples is out of range (1 to 100)",
                self.held_passes
            )));
        }
        if !(0.0..=2.0).contains(&self.image_weight_power) {
            return Err(ModelError::Invalid(format!(
                "image weight power {} is out of range (0 to 2)",
                self.image_weight_power
            )));
        }
        Ok(())
    }

    /// Whether no sample is added.
    pub fn is_none(&self) -> bool {
        self.samples(usize::MAX / 1024) == usize::MAX / 1024
    }

    fn mixtures(&self, n: usize) -> usize {
        if n < 2 {
            return 0;
        }
        (self.mixtures_per_brdf * n as f64).floor() as usize
    }

    fn floors(&self, n: usize) -> usize {
        (self.floors_per_brdf * n as f64).floor() as usize
    }

    fn permuted(&self, n: usize) -> usize {
        if self.rgb_permutations {
            5 * n
        } else {
            0
        }
    }

    /// The number of samples of a set of `n` BRDFs, originals included.
    pub fn samples(&self, n: usize) -> usize {
        n + self.permuted(n) + self.mixtures(n) + self.floors(n)
    }

    /// Sample `i` of a set of `n` BRDFs (`i < samples(n)`), drawn from `seed`.
    pub fn sample(&self, n: usize, i: usize, seed: u64) -> Sample {
        if i < n {
            return Sample::Original(i);
        }
        let j = i - n;
        if j < self.permuted(n) {
            return Sample::Permuted { index: j / 5, order: 1 + j % 5 };
        }
        let j = j - self.permuted(n);
        if j < self.mixtures(n) {
            let mut rng = stream(seed ^ 0xa06_3e71_u64, j);
            let a = rng.random_range(0..n);
            let b = (a + rng.random_range(1..n)) % n;
            let t = rng.random_range(0.25..0.75);
            return Sample::Mixture { a, b, t };
        }
        let mut rng = stream(seed ^ 0xf100_5ca1_u64, j - self.mixtures(n));
        let index = rng.random_range(0..n);
        let order = if self.rgb_permutations { rng.random_range(0..6) } else { 0 };
        let (lo, hi) = FLOOR_SCALES;
        let scale = (lo.ln() + rng.random_range(0.0..1.0) * (hi / lo).ln()).exp();
        Sample::Floor { index, order, scale }
    }
}

/// The generator of the `j`-th sample of one kind (`seed` already salted by the kind).
fn stream(seed: u64, j: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(j as u64);
    rng
}

/// The mapped layout (invalid cells 0) and the number of valid values of `sample` of `data`.
pub fn sample_layout(data: &TrainingSet, sample: Sample) -> crate::error::Result<(Vec<f32>, f64)> {
    if let Sample::Original(i) = sample {
        return Ok((data.input(i).to_vec(), data.valid_values(i)));
    }
    let reference = data.reference_layout().ok_or_else(|| {
        ModelError::Invalid(format!(
            "{}: augmentation needs the eq. (1) reference of the set (a set built from tables)",
            data.label()
        ))
    })?;
    let mut out = vec![0f32; LAYOUT_VALUES];
    let unmap = |x: f32, r: f32| inverse_log_relative(f64::from(x), f64::from(r));
    let map = |rho: f64, r: f32| {
        log_relative(rho.max(-deepbrdf_data::mapping::EPSILON), f64::from(r)) as f32
    };
    let valid = match sample {
        Sample::Original(_) => unreachable!("returned above"),
        Sample::Permuted { index, order } | Sample::Floor { index, order, .. } => {
            let (x, mask) = (data.input(index), data.mask(index));
            let perm = PERMUTATIONS[order];
            let floors = match sample {
                Sample::Floor { scale, .. } => {
                    diffuse_floors(data, index, reference).map(|d| (1.0 - scale) * d)
                }
                _ => [0.0; 3],
            };
            out.par_chunks_mut(PLANE).enumerate().for_each(|(image, o)| {
                let (slice, colour) = (image / 3, image % 3);
                let from = (slice * 3 + perm[colour]) * PLANE;
                let to = image * PLANE;
                let lowered = floors[perm[colour]];
                for (c, v) in o.iter_mut().enumerate() {
                    if mask[to + c] != 0.0 {
                        let rho = unmap(x[from + c], reference[from + c]);
                        let rho = if lowered == 0.0 { rho } else { (rho - lowered).max(0.0) };
                        *v = map(rho, reference[to + c]);
                    }
                }
            });
            data.valid_values(index)
        }
        Sample::Mixture { a, b, t } => {
            let (xa, xb) = (data.input(a), data.input(b));
            let (ma, mb) = (data.mask(a), data.mask(b));
            out.par_chunks_mut(PLANE).enumerate().for_each(|(image, o)| {
                let start = image * PLANE;
                for (c, v) in o.iter_mut().enumerate() {
                    let i = start + c;
                    if ma[i] != 0.0 && mb[i] != 0.0 {
                        let r = reference[i];
                        *v = map(t * unmap(xa[i], r) + (1.0 - t) * unmap(xb[i], r), r);
                    }
                }
            });
            ma.iter().zip(mb).filter(|(&p, &q)| p != 0.0 && q != 0.0).count() as f64
        }
    };
    Ok((out, valid))
}

/// The diffuse floor of each colour channel of BRDF `index`: the [`FLOOR_QUANTILE`] quantile of
/// the channel's valid linear values (0 where a channel has none).
fn diffuse_floors(data: &TrainingSet, index: usize, reference: &[f32]) -> [f64; 3] {
    let (x, mask) = (data.input(index), data.mask(index));
    std::array::from_fn(|colour| {
        let mut values: Vec<f64> = (0..N_PHI_D)
            .flat_map(|slice| {
                let start = (slice * 3 + colour) * PLANE;
                (start..start + PLANE).filter(|&i| mask[i] != 0.0)
            })
            .map(|i| inverse_log_relative(f64::from(x[i]), f64::from(reference[i])).max(0.0))
            .collect();
        if values.is_empty() {
            return 0.0;
        }
        let at = ((values.len() - 1) as f64 * FLOOR_QUANTILE) as usize;
        *values.select_nth_unstable_by(at, f64::total_cmp).1
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_data::MerlTable;

    fn set() -> TrainingSet {
        let a = MerlTable::from_fn(|h, d, _| {
            let v = 0.05 + 0.001 * (h + d) as f32;
            [v, 2.0 * v, 3.0 * v]
        });
        let b = MerlTable::from_fn(|h, _, p| {
            let v = 0.2 + 0.002 * h as f32 + 0.0001 * p as f32;
            [3.0 * v, v, 0.5 * v]
        });
        let reference = MedianReference::from_tables(&[&a, &b]).unwrap();
        TrainingSet::from_tables("t", &["a".into(), "b".into()], &[&a, &b], &reference).unwrap()
    }

    #[test]
    fn samples_enumerate_originals_permutations_and_mixtures() {
        let config = AugmentationConfig::preset();
        assert_eq!(config.samples(2), 2 + 10 + 8);
        assert_eq!(config.sample(2, 1, 0), Sample::Original(1));
        assert_eq!(config.sample(2, 2, 0), Sample::Permuted { index: 0, order: 1 });
        assert_eq!(config.sample(2, 11, 0), Sample::Permuted { index: 1, order: 5 });
        let Sample::Mixture { a, b, t } = config.sample(2, 12, 0) else { panic!("a mixture") };
        assert!(a != b && (0.25..0.75).contains(&t));
        assert_eq!(config.sample(2, 12, 0), config.sample(2, 12, 0));
        assert_eq!(AugmentationConfig::new().samples(5), 5);
        assert!(AugmentationConfig::new().is_none());
    }

    #[test]
    fn permutations_and_mixtures_are_computed_in_linear_space() {
        let data = set();
        let reference = data.reference_layout().unwrap().to_vec();
        let linear =
            |x: &[f32], i: usize| inverse_log_relative(f64::from(x[i]), f64::from(reference[i]));
        // Slice 7, a valid cell of image (7, colour): red and blue swapped (order [2, 1, 0]).
        let cell = (0..PLANE).find(|&c| data.mask(0)[(7 * 3) * PLANE + c] != 0.0).unwrap();
        let (swapped, valid) =
            sample_layout(&data, Sample::Permuted { index: 0, order: 5 }).unwrap();
        assert_eq!(valid, data.valid_values(0));
        let red = 7 * 3 * PLANE + cell;
        let blue = (7 * 3 + 2) * PLANE + cell;
        assert!((linear(&swapped, red) - linear(data.input(0), blue)).abs() < 1e-5);
        assert!((linear(&swapped, blue) - linear(data.input(0), red)).abs() < 1e-5);
        let (mixed, _) = sample_layout(&data, Sample::Mixture { a: 0, b: 1, t: 0.25 }).unwrap();
        let want = 0.25 * linear(data.input(0), red) + 0.75 * linear(data.input(1), red);
        assert!((linear(&mixed, red) - want).abs() < 1e-5 * want.abs().max(1.0));
        // Invalid cells stay 0.
        let invalid = (0..LAYOUT_VALUES).find(|&i| data.mask(0)[i] == 0.0).unwrap();
        assert_eq!(mixed[invalid], 0.0);
        let no_reference = TrainingSet::from_layouts(
            "x",
            vec!["a".into()],
            vec![data.input(0).to_vec()],
            vec![data.mask(0).to_vec()],
        )
        .unwrap();
        assert!(sample_layout(&no_reference, Sample::Permuted { index: 0, order: 1 }).is_err());
    }

    #[test]
    fn floor_samples_lower_each_channel_by_its_quantile_and_keep_the_rest() {
        let config =
            AugmentationConfig::new().with_rgb_permutations(true).with_floors_per_brdf(2.0);
        assert_eq!(config.samples(3), 3 + 15 + 6);
        assert!(!config.is_none());
        for i in 18..24 {
            let Sample::Floor { index, order, scale } = config.sample(3, i, 7) else {
                panic!("sample {i} is a floor sample")
            };
            assert!(index < 3 && order < 6, "{index} {order}");
            assert!((FLOOR_SCALES.0..=FLOOR_SCALES.1).contains(&scale), "{scale}");
        }
        let data = set();
        let reference = data.reference_layout().unwrap().to_vec();
        let floors = diffuse_floors(&data, 1, &reference);
        // Table b's channels are 3v, v, v/2 with v >= 0.2: floors in that order, above 0.1.
        assert!(floors[0] > floors[1] && floors[1] > floors[2] && floors[2] > 0.1, "{floors:?}");
        let scale = 0.25;
        let (lowered, valid) =
            sample_layout(&data, Sample::Floor { index: 1, order: 0, scale }).unwrap();
        assert_eq!(valid, data.valid_values(1));
        let linear =
            |x: &[f32], i: usize| inverse_log_relative(f64::from(x[i]), f64::from(reference[i]));
        let mut clamped = 0;
        for i in (0..LAYOUT_VALUES).filter(|&i| data.mask(1)[i] != 0.0).step_by(997) {
            let colour = (i / PLANE) % 3;
            let want = (linear(data.input(1), i) - (1.0 - scale) * floors[colour]).max(0.0);
            clamped += usize::from(want == 0.0);
            assert!((linear(&lowered, i) - want).abs() < 1e-5, "value {i}");
        }
        assert!(clamped == 0, "no valid value of b lies below 3/4 of its floor");
        assert!(AugmentationConfig::new().with_floors_per_brdf(101.0).validate().is_err());
    }
}

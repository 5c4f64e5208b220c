//! The reconstruction loss of eq. (4) (§3.2 "Loss Function"): only valid cells count, through
//! the *mask* function, and the error, squared (L2, the paper's choice) or absolute (L1, which
//! its Fig. 4 compares), is averaged over them.
//!
//! Eq. (4) sums `||mask(g(f(X))) - mask(X)||` over the training set; we use the mean over valid
//! values of the squared difference, which has the same minimiser, keeps the learning rate
//! independent of the batch size, and equals the mapped-space MSE the evaluation reports.
//!
//! [`colour_weights`] weighs a training sample's colour channels in that error by how much a
//! mapped error moves a rendering of the sample, relative to the rendering's brightness (not in
//! the paper): the image-space RelAE the evaluation reports.

use burn::prelude::*;
use deepbrdf_data::layout::layout_index;
use deepbrdf_data::mapping::EPSILON;
use deepbrdf_data::merl::grid::cos_weights;
use deepbrdf_data::merl::{cell_index, N_PHI_D, N_THETA_D, N_THETA_H};
use serde::{Deserialize, Serialize};

/// The norm of eq. (4): "evaluated either under L1 or L2" (§3.2); the paper keeps L2 and
/// shows the difference in its Fig. 4.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LossNorm {
    /// The squared error (the paper's and the default).
    #[default]
    L2,
    /// The absolute error.
    L1,
}

impl LossNorm {
    /// The per-value error of the differences `diff`: their squares (L2) or absolute values
    /// (L1).
    pub fn error<const D: usize>(self, diff: Tensor<D>) -> Tensor<D> {
        match self {
            Self::L2 => diff.clone() * diff,
            Self::L1 => diff.abs(),
        }
    }

    /// The norm's name in configurations and results (`l2`, `l1`).
    pub fn name(self) -> &'static str {
        match self {
            Self::L2 => "l2",
            Self::L1 => "l1",
        }
    }
}

/// Mean squared error over the cells where `mask` is 1 (eq. 4, L2).
///
/// # Shapes
/// - prediction, target, mask: `[batch, 540, 90, 90]` (any equal shape)
/// - output: `[1]`
pub fn masked_mse<const D: usize>(
    prediction: Tensor<D>,
    target: Tensor<D>,
    mask: Tensor<D>,
) -> Tensor<1> {
    let valid = mask.clone().sum().clamp_min(1.0); // [1]
    let diff = (prediction - target) * mask; // [batch, 540, 90, 90]
    (diff.clone() * diff).sum() / valid // [1]
}

/// Eq. (4) under `norm` for a network predicting deviations from a fixed offset mu: with the
/// output `deviation + mu`, `(output - x) * mask = deviation * mask - (x - mu) * mask`, so the
/// offset never enters the graph. `centred_target` is `(x - mu) * mask`; `valid` counts the
/// valid values (the sum of `mask`, known before the batch is built).
///
/// # Shapes
/// - deviation, centred_target, mask: `[batch, 540, 90, 90]`
/// - output: `[1]`
pub fn masked_error_centred(
    deviation: Tensor<4>,
    centred_target: Tensor<4>,
    mask: Tensor<4>,
    valid: f64,
    norm: LossNorm,
) -> Tensor<1> {
    let diff = deviation * mask - centred_target; // [batch, 540, 90, 90]
    norm.error(diff).sum().div_scalar(valid.max(1.0)) // [1]
}

/// The image-space weights `(S_c / R)^(2 power)` of the three colour channels of a mapped layout
/// (`540 * 90 * 90` values, invalid cells 0; `reference`: eq. (1)'s reference in layout order).
///
/// Eq. (1) has slope `d rho / d rho' = rho + rho_ref + 2 eps = (rho_ref + eps) e^rho'`: a mapped
/// error `delta` in a cell moves the cosine-weighted radiance a rendering sees there by about
/// `delta (rho_ref + eps) e^rho' cos theta_i cos theta_o`. `S_c` sums that sensitivity over the
/// valid cells of channel c, `R` the cosine-weighted linear values `rho + eps` over all three
/// channels (divided by 3): a uniform mapped error `delta` moves the rendering by about
/// `delta S_c / R` of its brightness. A dark material (`rho` far below the median reference) has
/// a large ratio (its RelAE is large for a mapped error that is small), a bright one a ratio
/// near 1. Cells are valid where their cosine product is positive and their mapped value is not
/// exactly 0 (invalid cells are 0; a valid value is 0 only for `rho = -eps`). Power 0 gives 1.
pub fn colour_weights(layout: &[f32], reference: &[f32], power: f64) -> [f64; 3] {
    if power == 0.0 {
        return [1.0; 3];
    }
    let cos = cos_weights();
    let (mut sensitivity, mut brightness) = ([0f64; 3], 0f64);
    for h in 0..N_THETA_H {
        for d in 0..N_THETA_D {
            for p in 0..N_PHI_D {
                let weight = f64::from(cos[cell_index(h, d, p)]);
                if weight <= 0.0 {
                    continue;
                }
                for c in 0..3 {
                    let i = layout_index(h, d, p, c);
                    if layout[i] == 0.0 {
                        continue;
                    }
                    let scale = f64::from(reference[i]) + EPSILON;
                    let grown = f64::from(layout[i]).exp();
                    sensitivity[c] += weight * scale * grown;
                    brightness += weight * scale * (grown - 1.0);
                }
            }
        }
    }
    let brightness = brightness / 3.0;
    sensitivity.map(|s| match brightness > 0.0 && s > 0.0 {
        true => (s / brightness).powf(2.0 * power),
        false => 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::TensorData;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_centred_form_equals_the_plain_one() {
        // Seeded values (not Burn's shared generator, which other tests seed concurrently).
        let device = Device::default();
        let shape = [2, 3, 4, 5];
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut uniform = |lo: f32, hi: f32| {
            let values: Vec<f32> = (0..120).map(|_| rng.random_range(lo..hi)).collect();
            Tensor::<4>::from_data(TensorData::new(values, shape), &device)
        };
        let x = uniform(0.0, 2.0);
        let mu = uniform(0.0, 1.0);
        let dev = uniform(-1.0, 1.0);
        let mask = uniform(0.0, 1.0).greater_elem(0.3).float();
        let valid: f32 = mask.clone().sum().into_scalar();
        assert!(valid > 60.0 && valid < 120.0, "{valid} valid cells");
        let plain: f32 =
            masked_mse(dev.clone() + mu.clone(), x.clone(), mask.clone()).into_scalar();
        let centred: f32 = masked_error_centred(
            dev.clone(),
            (x.clone() - mu.clone()) * mask.clone(),
            mask.clone(),
            f64::from(valid),
            LossNorm::L2,
        )
        .into_scalar();
        assert!(plain > 0.1, "{plain}");
        assert!((plain - centred).abs() <= 1e-5 * plain.abs(), "{plain} vs {centred}");
        // L1: the mean absolute error over the valid cells.
        let absolute: f32 =
            ((dev.clone() + mu.clone() - x.clone()).abs() * mask.clone()).sum().into_scalar();
        let l1: f32 = masked_error_centred(
            dev,
            (x - mu) * mask.clone(),
            mask,
            f64::from(valid),
            LossNorm::L1,
        )
        .into_scalar();
        let want = absolute / valid;
        assert!((l1 - want).abs() <= 1e-5 * want, "{l1} vs {want}");
        assert!((l1 - centred).abs() > 1e-3, "L1 {l1} and L2 {centred} differ");
    }

    #[test]
    fn loss_norms_are_named_in_lower_case() {
        assert_eq!(serde_json::to_string(&LossNorm::L1).unwrap(), "\"l1\"");
        assert_eq!(serde_json::from_str::<LossNorm>("\"l2\"").unwrap(), LossNorm::L2);
        assert!(serde_json::from_str::<LossNorm>("\"l3\"").is_err());
        assert_eq!(LossNorm::default().name(), "l2");
    }

    #[test]
    fn colour_weights_grow_as_a_channel_darkens_against_the_reference() {
        use deepbrdf_data::layout::{LAYOUT_VALUES, PLANE};
        use deepbrdf_data::mapping::log_relative;
        // rho = rho_ref in all channels: S_c = 2 R (the slope is 2 (rho + eps)) for every c.
        let reference = vec![0.1f32; LAYOUT_VALUES];
        let even = vec![log_relative(0.1, 0.1) as f32; LAYOUT_VALUES];
        for w in colour_weights(&even, &reference, 0.5) {
            assert!((w - 2.0).abs() < 1e-6, "{w}");
        }
        assert_eq!(colour_weights(&even, &reference, 0.0), [1.0; 3]);
        // A material 10 x darker than the reference in every channel: the ratio is
        // (rho + rho_ref + 2 eps) / (rho + eps) = 0.112 / 0.011.
        let dark = vec![log_relative(0.01, 0.1) as f32; LAYOUT_VALUES];
        let want = 0.112 / 0.011;
        for w in colour_weights(&dark, &reference, 0.5) {
            assert!((w / want - 1.0).abs() < 1e-4, "{w} vs {want}");
        }
        // Power 1 squares it; invalid (zero) cells do not count (here one phi_d slice, all three
        // channels, so the ratio stays).
        let mut holed = dark.clone();
        holed[..3 * PLANE].fill(0.0);
        for w in colour_weights(&holed, &reference, 1.0) {
            assert!((w / (want * want) - 1.0).abs() < 1e-3, "{w}");
        }
    }

    #[test]
    fn invalid_cells_do_not_count() {
        let device = Device::default();
        // Two valid cells with errors 1 and 3 -> (1 + 9) / 2 = 5; the invalid cell's error of
        // 100 is ignored, whatever its value.
        let prediction = Tensor::<1>::from_floats([1.0, 3.0, 100.0], &device);
        let target = Tensor::<1>::from_floats([0.0, 0.0, 0.0], &device);
        let mask = Tensor::<1>::from_floats([1.0, 1.0, 0.0], &device);
        let loss: f32 = masked_mse(prediction, target.clone(), mask.clone()).into_scalar();
        assert!((loss - 5.0).abs() < 1e-6, "{loss}");
        let prediction = Tensor::<1>::from_floats([1.0, 3.0, -7.0e6], &device);
        let loss: f32 = masked_mse(prediction, target, mask).into_scalar();
        assert!((loss - 5.0).abs() < 1e-6, "{loss}");
    }

    #[test]
    fn an_all_invalid_batch_has_zero_loss() {
        let device = Device::default();
        let x = Tensor::<2>::ones([2, 3], &device);
        let loss: f32 = masked_mse(x.clone(), x.zeros_like(), x.zeros_like()).into_scalar();
        assert_eq!(loss, 0.0);
    }
}

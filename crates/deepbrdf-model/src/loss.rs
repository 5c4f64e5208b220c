//! The reconstruction loss of eq. (4) with the L2 norm (§3.2 "Loss Function"): only valid cells
//! count, through the *mask* function, and the squared error is averaged over them.
//!
//! Eq. (4) sums `||mask(g(f(X))) - mask(X)||` over the training set; we use the mean over valid
//! values of the squared difference, which has the same minimiser, keeps the learning rate
//! independent of the batch size, and equals the mapped-space MSE the evaluation reports.

use burn::prelude::*;

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

/// Eq. (4), L2, for a network predicting deviations from a fixed offset mu: with the output
/// `deviation + mu`, `((output - x) * mask)^2 = (deviation * mask - (x - mu) * mask)^2`, so the
/// offset never enters the graph. `centred_target` is `(x - mu) * mask`; `valid` counts the
/// valid values (the sum of `mask`, known before the batch is built).
///
/// # Shapes
/// - deviation, centred_target, mask: `[batch, 540, 90, 90]`
/// - output: `[1]`
pub fn masked_mse_centred(
    deviation: Tensor<4>,
    centred_target: Tensor<4>,
    mask: Tensor<4>,
    valid: f64,
) -> Tensor<1> {
    let diff = deviation * mask - centred_target; // [batch, 540, 90, 90]
    (diff.clone() * diff).sum().div_scalar(valid.max(1.0)) // [1]
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
        let centred: f32 =
            masked_mse_centred(dev, (x - mu) * mask.clone(), mask, f64::from(valid)).into_scalar();
        assert!(plain > 0.1, "{plain}");
        assert!((plain - centred).abs() <= 1e-5 * plain.abs(), "{plain} vs {centred}");
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

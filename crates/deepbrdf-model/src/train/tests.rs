//! The loop with a network that is not the autoencoder: a small MLP regressor (7 -> 16 -> 3,
//! in-memory pairs), the shape of the editing regressor of eq. (7). Its [`TrainStep`] is the
//! whole of what such a network adds to the loop.

use burn::nn::{Linear, LinearConfig};
use burn::optim::{GradientsParams, MultiGradientsParams};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;
use burn::tensor::TensorData;
use deepbrdf_data::Silent;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::error::{ModelError, Result};

#[derive(Module, Debug)]
struct Mlp {
    hidden: Linear,
    out: Linear,
}

/// A regressor from `n` inputs to `k` outputs on in-memory pairs.
struct Regressor {
    inputs: Vec<Vec<f32>>,
    targets: Vec<Vec<f32>>,
    hidden: usize,
    seed: u64,
}

impl TrainStep for Regressor {
    type Model = Mlp;

    fn init(&mut self, device: &Device) -> Result<Mlp> {
        let (n, k) = (self.inputs[0].len(), self.targets[0].len());
        Ok(crate::seeded::with_seed(self.seed, device, || Mlp {
            hidden: LinearConfig::new(n, self.hidden).init(device),
            out: LinearConfig::new(self.hidden, k).init(device),
        }))
    }

    fn step(
        &mut self,
        model: &Mlp,
        _epoch: usize,
        indices: &[usize],
        device: &Device,
    ) -> Result<(f32, MultiGradientsParams)> {
        let rows = |v: &[Vec<f32>]| {
            let data: Vec<f32> = indices.iter().flat_map(|&i| v[i].clone()).collect();
            Tensor::<2>::from_data(TensorData::new(data, [indices.len(), v[0].len()]), device)
        };
        let (x, y) = (rows(&self.inputs), rows(&self.targets));
        let diff = model.out.forward(leaky_relu(model.hidden.forward(x), 0.01)) - y;
        let loss = (diff.clone() * diff).mean(); // [1]
        let value: f32 = loss.clone().into_scalar();
        Ok((value, on_device(GradientsParams::from_grads(loss.backward(), model), device)))
    }
}

/// `n` pairs: 7 seeded inputs in [-1, 1], 3 smooth functions of them times `scale`.
fn pairs(n: usize, scale: f32) -> Regressor {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let inputs: Vec<Vec<f32>> =
        (0..n).map(|_| (0..7).map(|_| rng.random_range(-1.0..1.0f32)).collect()).collect();
    let targets = inputs
        .iter()
        .map(|x| {
            let s: f32 = x.iter().sum();
            vec![scale * (s / 3.0).tanh(), scale * x[0] * x[1], scale * (x[2] - 0.5 * x[6])]
        })
        .collect();
    Regressor { inputs, targets, hidden: 16, seed: 5 }
}

fn settings() -> LoopConfig {
    LoopConfig::new(adam())
        .with_learning_rate(1e-2)
        .with_final_lr_factor(0.1)
        .with_epochs(30)
        .with_batch_size(8)
        .with_seed(3)
        .with_checkpoint_seconds(0.0)
}

fn identity() -> serde_json::Value {
    serde_json::json!({"network": "regressor 7-16-3", "loop": settings()})
}

fn train_regressor(step: &mut Regressor, session: &Session<'_>) -> Result<Outcome<Mlp>> {
    let device = crate::DeviceKind::default_kind().unwrap().device().unwrap();
    run(&settings(), &identity(), "pairs-v1", step.inputs.len(), step, session, &device)
}

/// The weights' bytes, without Burn's random parameter ids.
fn weights(model: &Mlp) -> Vec<u8> {
    let bytes = model.valid().into_record().into_bytes().unwrap().to_vec();
    crate::record::rewrite(bytes, false, |name| name).unwrap()
}

#[test]
fn a_small_regressor_trains_through_the_loop() {
    let dir = tempfile::tempdir().unwrap();
    let mut step = pairs(40, 1.0);
    let trained =
        train_regressor(&mut step, &Session::new(dir.path(), false, &Silent, "mlp")).unwrap();
    let (first, last) = (trained.log[0].loss, trained.log.last().unwrap().loss);
    assert_eq!(trained.log.len(), 30);
    assert!(last < 0.2 * first, "loss {first} -> {last}");
    let csv = std::fs::read_to_string(dir.path().join(LOG_FILE)).unwrap();
    assert_eq!(csv, log::log_csv(&trained.log));
    assert_eq!(csv.lines().count(), 31);
    let saved: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join(CONFIG_FILE)).unwrap()).unwrap();
    assert!(json_close(&saved, &identity()));
    // The same seed gives the same weights in another directory.
    let other = tempfile::tempdir().unwrap();
    let again =
        train_regressor(&mut pairs(40, 1.0), &Session::new(other.path(), false, &Silent, "mlp"))
            .unwrap();
    assert_eq!(weights(&again.model), weights(&trained.model));
}

#[test]
fn an_abandoned_regressor_run_resumes_to_the_same_bits() {
    // 5 batches per epoch, the last one short; killed in the middle of epoch 7 after a
    // checkpoint within the epoch (one is written after every batch here).
    let straight_dir = tempfile::tempdir().unwrap();
    let session = Session::new(straight_dir.path(), false, &Silent, "mlp");
    let straight = train_regressor(&mut pairs(37, 1.0), &session).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let killed = Session::new(dir.path(), false, &Silent, "mlp").killed_after(6, 2);
    assert!(train_regressor(&mut pairs(37, 1.0), &killed).is_err());
    // Not without `resume`; not with other data.
    let fresh = Session::new(dir.path(), false, &Silent, "mlp");
    let err = train_regressor(&mut pairs(37, 1.0), &fresh).unwrap_err();
    assert!(err.to_string().contains("already holds a training run"), "{err}");
    let resume = Session::new(dir.path(), true, &Silent, "mlp");
    let device = crate::DeviceKind::default_kind().unwrap().device().unwrap();
    let mut step = pairs(37, 1.0);
    let err = run(&settings(), &identity(), "other", 37, &mut step, &resume, &device).unwrap_err();
    assert!(err.to_string().contains("other data"), "{err}");
    let resumed = train_regressor(&mut pairs(37, 1.0), &resume).unwrap();
    assert_eq!(
        resumed.log.iter().map(|r| r.loss).collect::<Vec<_>>(),
        straight.log.iter().map(|r| r.loss).collect::<Vec<_>>()
    );
    assert_eq!(weights(&resumed.model), weights(&straight.model));
    let read = |d: &std::path::Path| std::fs::read(d.join(LOG_FILE)).unwrap();
    assert_eq!(read(dir.path()), read(straight_dir.path()));
}

#[test]
fn a_run_out_of_time_stops_at_an_epoch_end_and_resumes_to_the_same_bits() {
    let straight_dir = tempfile::tempdir().unwrap();
    let session = Session::new(straight_dir.path(), false, &Silent, "mlp");
    let straight = train_regressor(&mut pairs(37, 1.0), &session).unwrap();

    // A limit already passed: the run stops at the end of its first epoch, with a checkpoint.
    let dir = tempfile::tempdir().unwrap();
    let limited = Session::new(dir.path(), false, &Silent, "mlp")
        .with_time_limit(Some(std::time::Duration::ZERO));
    let first = train_regressor(&mut pairs(37, 1.0), &limited).unwrap();
    assert_eq!(first.log.len(), 1);
    assert_eq!(first.log[0].loss, straight.log[0].loss);
    assert!(dir.path().join(CHECKPOINT_FILE).is_file());
    // Twice more under the same limit: one epoch each.
    let again = Session::new(dir.path(), true, &Silent, "mlp")
        .with_time_limit(Some(std::time::Duration::ZERO));
    assert_eq!(train_regressor(&mut pairs(37, 1.0), &again).unwrap().log.len(), 2);
    assert_eq!(train_regressor(&mut pairs(37, 1.0), &again).unwrap().log.len(), 3);
    // Without a limit it finishes exactly as the uninterrupted run.
    let resume = Session::new(dir.path(), true, &Silent, "mlp");
    let resumed = train_regressor(&mut pairs(37, 1.0), &resume).unwrap();
    assert_eq!(resumed.log.len(), 30);
    assert_eq!(weights(&resumed.model), weights(&straight.model));
}

#[test]
fn a_diverging_regressor_stops_with_a_clear_error() {
    // Targets of 1e30: the squared error overflows f32 on the first batch.
    let dir = tempfile::tempdir().unwrap();
    let mut step = pairs(16, 1e30);
    let err =
        train_regressor(&mut step, &Session::new(dir.path(), false, &Silent, "mlp")).unwrap_err();
    assert!(matches!(err, ModelError::NonFinite { epoch: 1, batch: 1, .. }), "{err}");
    let text = err.to_string();
    assert!(text.contains("diverged") && text.contains("no checkpoint"), "{text}");
    assert!(!dir.path().join(LOG_FILE).exists());
}

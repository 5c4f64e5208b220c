//! Tests of the autoencoder's training: the loss falls on every CPU backend, training a slice
//! network on coefficients equals the full eq. (4), exact resume (with and without slice
//! dropout), bad checkpoints and configuration files, divergence, thread-count independence.

use burn::optim::AdamConfig;
use deepbrdf_data::augment::SliceSelection;
use deepbrdf_data::Silent;

use super::batch::{batch_tensors, Augment};
use super::*;
use crate::autoencoder::{AutoencoderConfig, ConvolutionalConfig, INPUT_SIDE};
use crate::device::DeviceKind;
use crate::train::{adam, CHECKPOINT_FILE, LOG_FILE};

/// A network with Table 1's strides and kernels but one or two channels per layer.
fn tiny_config(mean_offset: bool) -> TrainConfig {
    let layers = ConvolutionalConfig::new()
        .with_projection(Some(2))
        .with_encoder_channels([2, 2, 2])
        .with_residual_blocks(1)
        .with_decoder_channels([2, 2])
        .with_mean_offset(mean_offset);
    TrainConfig::new(AutoencoderConfig::convolutional(2, layers), AdamConfig::new())
        .with_learning_rate(3e-2)
        .with_epochs(6)
        .with_batch_size(2)
        .with_seed(7)
        .with_checkpoint_seconds(0.0)
}

/// Smooth synthetic layouts: a per-BRDF level and slope over theta_h rows, invalid cells
/// (a corner of each image) masked.
fn tiny_set(n: usize) -> TrainingSet {
    let mut inputs = Vec::new();
    let mut masks = Vec::new();
    for b in 0..n {
        let level = 0.5 + 0.3 * b as f32;
        let mut input = vec![0f32; INPUT_VALUES];
        let mut mask = vec![0f32; INPUT_VALUES];
        for (i, (v, m)) in input.iter_mut().zip(mask.iter_mut()).enumerate() {
            let row = (i / INPUT_SIDE) % INPUT_SIDE;
            let col = i % INPUT_SIDE;
            if row + col < 150 {
                *m = 1.0;
                *v = level + 0.01 * row as f32 * (1.0 + b as f32);
            }
        }
        inputs.push(input);
        masks.push(mask);
    }
    let names = (0..n).map(|b| format!("synthetic-{b}")).collect();
    TrainingSet::from_layouts("synthetic", names, inputs, masks).unwrap()
}

/// Four BRDFs spanning three directions around a mean, a mask with every 11th value invalid:
/// k = 1 leaves a linear fit far from exact.
fn mixed_set() -> TrainingSet {
    let pattern = |i: usize| {
        [((i % 7) as f32 - 3.0) / 3.0, ((i % 5) as f32 - 2.0) / 2.0, (i % 3) as f32 - 1.0]
    };
    let mix = [[1.0, 0.0, 0.3], [-0.5, 1.0, -0.2], [-0.5, -1.0, 0.4], [0.2, 0.4, -0.9]];
    let mask: Vec<f32> = (0..INPUT_VALUES).map(|i| if i % 11 == 0 { 0.0 } else { 1.0 }).collect();
    let inputs: Vec<Vec<f32>> = mix
        .iter()
        .map(|w| {
            (0..INPUT_VALUES)
                .map(|i| {
                    let p = pattern(i);
                    (1.0 + w[0] * p[0] + w[1] * p[1] + w[2] * p[2]) * mask[i]
                })
                .collect()
        })
        .collect();
    let names = (0..4).map(|b| format!("mixed-{b}")).collect();
    TrainingSet::from_layouts("mixed", names, inputs, vec![mask; 4]).unwrap()
}

fn device() -> Device {
    DeviceKind::default_kind().unwrap().device().unwrap()
}

fn losses(t: &Trained) -> Vec<(usize, f64)> {
    t.log.iter().map(|r| (r.epoch, r.loss)).collect()
}

#[test]
fn the_loss_falls_on_every_compiled_backend() {
    let set = tiny_set(2);
    let config = tiny_config(false).with_epochs(8).with_batch_size(1).with_learning_rate(5e-2);
    for kind in DeviceKind::available() {
        if matches!(kind, DeviceKind::Wgpu | DeviceKind::Cuda) {
            continue; // GPU backends are exercised on GPU machines, not in CI.
        }
        let device = kind.device().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let trained = train(&config, &set, dir.path(), false, &Silent, &device).unwrap();
        let first = trained.log.first().unwrap().loss;
        let last = trained.log.last().unwrap().loss;
        assert!(last < 0.7 * first, "{kind}: loss {first} -> {last}");
        assert_eq!(trained.log.len(), 8);
        assert!(trained.mean_mse() < 0.7 * first, "{kind}: {}", trained.mean_mse());
        let csv = std::fs::read_to_string(dir.path().join(LOG_FILE)).unwrap();
        assert_eq!(csv.lines().count(), 9, "{csv}");
        assert_eq!(saved_config(dir.path()).unwrap().to_string(), config.to_string());
    }
}

#[test]
fn a_killed_run_resumes_to_the_same_result() {
    // 2 batches per epoch, the last one short. One shard per batch.
    let set = tiny_set(3);
    let config = tiny_config(true).with_epochs(2).with_final_lr_factor(0.1).with_threads(1);
    let straight_dir = tempfile::tempdir().unwrap();
    let straight = train(&config, &set, straight_dir.path(), false, &Silent, &device()).unwrap();

    let dir = tempfile::tempdir().unwrap();
    // Killed in the middle of epoch 2: its first batch is applied but never saved.
    let session = Session::new(dir.path(), false, &Silent, "test").killed_after(1, 0);
    assert!(train_in(&config, &set, &session, &device()).is_err());
    // Without `resume`, an existing run is never overwritten.
    assert!(train(&config, &set, dir.path(), false, &Silent, &device()).is_err());
    // Another configuration cannot continue it.
    let other = config.clone().with_learning_rate(1e-3);
    let err = train(&other, &set, dir.path(), true, &Silent, &device()).unwrap_err();
    assert!(err.to_string().contains("configuration"), "{err}");
    let resumed = train(&config, &set, dir.path(), true, &Silent, &device()).unwrap();

    assert_eq!(losses(&resumed), losses(&straight));
    assert_eq!(resumed.per_material_mse, straight.per_material_mse);
    // A finished run resumes to itself.
    let again = train(&config, &set, dir.path(), true, &Silent, &device()).unwrap();
    assert_eq!(again.per_material_mse, straight.per_material_mse);
}

#[test]
fn a_killed_slice_run_with_slice_dropout_resumes_to_the_same_result() {
    // The slice preset's kind of run: coefficients, slice dropout drawn per (seed, epoch, BRDF)
    // with probability 1/2. Batches of 2: killed after the first batch of epoch 3, with a
    // checkpoint after every batch; the resumed run must draw the same dropout and reach the
    // same weights as the straight one.
    let set = mixed_set();
    let dropout =
        SliceDropoutConfig::new().with_selections(vec!["every:3".into(), "random:20".into()]);
    let config = slice_config(4).with_slice_dropout(Some(dropout));
    let straight_dir = tempfile::tempdir().unwrap();
    let straight = train(&config, &set, straight_dir.path(), false, &Silent, &device()).unwrap();
    let without = config.clone().with_slice_dropout(None);
    let plain_dir = tempfile::tempdir().unwrap();
    let plain = train(&without, &set, plain_dir.path(), false, &Silent, &device()).unwrap();
    assert_ne!(losses(&plain), losses(&straight), "the dropout must change the batches");

    let dir = tempfile::tempdir().unwrap();
    let session = Session::new(dir.path(), false, &Silent, "test").killed_after(2, 0);
    assert!(train_in(&config, &set, &session, &device()).is_err());
    let resumed = train(&config, &set, dir.path(), true, &Silent, &device()).unwrap();
    assert_eq!(losses(&resumed), losses(&straight));
    assert_eq!(resumed.per_material_mse, straight.per_material_mse);
    let read = |d: &Path| std::fs::read(d.join(LOG_FILE)).unwrap();
    assert_eq!(read(dir.path()), read(straight_dir.path()));
}

#[test]
fn the_thread_count_does_not_change_a_slice_run() {
    // Rayon's pool size must not enter any sum (basis fit, projections, evaluation).
    let set = mixed_set();
    let config = slice_config(20).with_slice_dropout(Some(SliceDropoutConfig::new()));
    let in_pool = |threads: usize| {
        let dir = tempfile::tempdir().unwrap();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let trained =
            pool.install(|| train(&config, &set, dir.path(), false, &Silent, &device())).unwrap();
        let log = std::fs::read(dir.path().join(LOG_FILE)).unwrap();
        (losses(&trained), trained.per_material_mse, log)
    };
    assert_eq!(in_pool(1), in_pool(3));
}

#[test]
fn a_damaged_checkpoint_is_reported_not_used() {
    let set = tiny_set(2);
    let config = tiny_config(false).with_epochs(1);
    let dir = tempfile::tempdir().unwrap();
    train(&config, &set, dir.path(), false, &Silent, &device()).unwrap();
    let path = dir.path().join(CHECKPOINT_FILE);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = train(&config, &set, dir.path(), true, &Silent, &device()).unwrap_err();
    assert!(err.to_string().contains("checkpoint.bin"), "{err}");
}

#[test]
fn a_bad_configuration_file_is_named_with_its_problem() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.json");
    std::fs::write(&good, TrainConfig::slice(5).with_epochs(3).to_string()).unwrap();
    let read = TrainConfig::from_file(&good).unwrap();
    assert_eq!(read.to_string(), TrainConfig::slice(5).with_epochs(3).to_string());
    let slice = TrainConfig::slice(5).to_string();
    let cases = [
        ("truncated.json", slice[..40].to_string(), "EOF"),
        ("typo.json", slice.replace("\"epochs\"", "\"epocs\""), "epochs"),
        ("zero.json", TrainConfig::slice(5).with_batch_size(0).to_string(), "batches of 0"),
        (
            "k.json",
            slice.replace("\"components\": 40", "\"components\": 3"),
            "3 principal components for k = 5",
        ),
        ("retired.json", retired_cpu_config(), "retired"),
        ("text.json", "epochs = 3".to_string(), "not a training configuration"),
    ];
    for (name, text, problem) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let err = TrainConfig::from_file(&path).unwrap_err().to_string();
        assert!(err.contains(name) && err.contains(problem), "{name}: {err}");
    }
    let missing = dir.path().join("missing.json");
    let err = TrainConfig::from_file(&missing).unwrap_err().to_string();
    assert!(err.contains("missing.json"), "{err}");
}

#[test]
fn a_diverging_run_stops_and_keeps_its_last_checkpoint() {
    // Values of 3e19 square to more than f32::MAX: the first loss is infinite.
    let set = tiny_set(2);
    let huge = TrainingSet::from_layouts(
        "huge",
        set.names().to_vec(),
        vec![vec![3e19; INPUT_VALUES]; 2],
        vec![set.mask(0).to_vec(), set.mask(1).to_vec()],
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let err = train(&tiny_config(false), &huge, dir.path(), false, &Silent, &device()).unwrap_err();
    assert!(matches!(err, ModelError::NonFinite { epoch: 1, batch: 1, .. }), "{err}");
    assert!(err.to_string().contains("no checkpoint"), "{err}");
}

#[test]
fn slice_dropout_fills_inputs_but_keeps_targets() {
    // Every layout channel holds its own index, so a filled slice is visible.
    let plane = INPUT_SIDE * INPUT_SIDE;
    let layout: Vec<f32> = (0..INPUT_VALUES).map(|i| (i / plane) as f32).collect();
    let set = TrainingSet::from_layouts(
        "channels",
        vec!["a".into(), "b".into()],
        vec![layout.clone(), layout],
        vec![vec![1.0; INPUT_VALUES]; 2],
    )
    .unwrap();
    let selections = [SliceSelection::Every(9)];
    let augment = Augment { probability: 1.0, selections: &selections, seed: 3, epoch: 0 };
    let b = batch_tensors(&set, &[1], Some(&augment), None, &device());
    let input: Vec<f32> = b.input.into_data().try_into_vec().unwrap();
    let target: Vec<f32> = b.target.into_data().try_into_vec().unwrap();
    assert_eq!(target, set.input(1));
    // Slice 1 (channels 3..6) is filled from slice 0 (every 9th slice from 0 is kept).
    let slice = 3 * INPUT_SIDE * INPUT_SIDE;
    assert_eq!(input[slice..2 * slice], input[..slice]);
    assert_ne!(input[slice..2 * slice], target[slice..2 * slice]);
    // Slice 9 is kept.
    assert_eq!(input[9 * slice..10 * slice], target[9 * slice..10 * slice]);
    let dropout = SliceDropoutConfig::new().with_selections(vec!["every:0".into()]);
    assert!(dropout.parsed().is_err());
}

/// [`mixed_set`]'s layouts with every value valid (so the slice network's coefficient loss
/// is eq. (4) exactly).
fn valid_set() -> TrainingSet {
    let set = mixed_set();
    let inputs = (0..set.len()).map(|i| set.input(i).to_vec()).collect();
    TrainingSet::from_layouts(
        "valid",
        set.names().to_vec(),
        inputs,
        vec![vec![1.0; INPUT_VALUES]; 4],
    )
    .unwrap()
}

fn slice_config(epochs: usize) -> TrainConfig {
    use crate::augmentation::AugmentationConfig;
    use crate::autoencoder::{Architecture, SliceConfig};
    let layers = SliceConfig::new()
        .with_directions(12)
        .with_components(3)
        .with_hidden(Some(16))
        .with_augmentation(AugmentationConfig::new());
    TrainConfig::new(AutoencoderConfig::new(1, Architecture::Slice(layers)), adam())
        .with_learning_rate(1e-2)
        .with_final_lr_factor(0.05)
        .with_epochs(epochs)
        .with_batch_size(2)
        .with_seed(5)
        .with_checkpoint_seconds(0.0)
}

#[test]
fn slice_training_on_coefficients_matches_the_full_loss_and_resumes() {
    let set = valid_set();
    let config = slice_config(60);
    let dir = tempfile::tempdir().unwrap();
    let trained = train(&config, &set, dir.path(), false, &Silent, &device()).unwrap();
    let (first, last) = (trained.log[0].loss, trained.log.last().unwrap().loss);
    assert!(last < 0.7 * first, "loss {first} -> {last}");
    let full = trained.mean_mse();
    assert!((full - last).abs() <= 2e-2 * full, "coefficients {last} vs full {full}");
    // Killed in epoch 2 of a short run, then resumed: the same run.
    let short = config.clone().with_epochs(3);
    let straight_dir = tempfile::tempdir().unwrap();
    let straight = train(&short, &set, straight_dir.path(), false, &Silent, &device()).unwrap();
    let killed = tempfile::tempdir().unwrap();
    let session = Session::new(killed.path(), false, &Silent, "test").killed_after(1, 0);
    assert!(train_in(&short, &set, &session, &device()).is_err());
    let resumed = train(&short, &set, killed.path(), true, &Silent, &device()).unwrap();
    assert_eq!(losses(&resumed), losses(&straight));
    assert_eq!(resumed.per_material_mse, straight.per_material_mse);
    // Augmentation needs the set's eq. (1) reference, which a set of layouts lacks.
    let mut augmented = slice_config(1);
    if let crate::autoencoder::Architecture::Slice(s) = &mut augmented.model.architecture {
        s.augmentation = crate::augmentation::AugmentationConfig::preset();
    }
    let other = tempfile::tempdir().unwrap();
    let err = train(&augmented, &set, other.path(), false, &Silent, &device()).unwrap_err();
    assert!(err.to_string().contains("reference"), "{err}");
    // So does the image-space weighting of the loss.
    let mut weighted = slice_config(1);
    if let crate::autoencoder::Architecture::Slice(s) = &mut weighted.model.architecture {
        s.augmentation =
            crate::augmentation::AugmentationConfig::new().with_image_weight_power(0.5);
    }
    let err = train(&weighted, &set, other.path(), false, &Silent, &device()).unwrap_err();
    assert!(err.to_string().contains("image-space weighting"), "{err}");
}

#[test]
fn the_image_space_weighting_favours_the_dark_material() {
    use crate::augmentation::AugmentationConfig;
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_data::MerlTable;
    // Two materials unlike each other: one dark (1/20 of the reference), one bright. A network
    // with k = 1 cannot fit both; weighting the loss by image-space sensitivity gives the dark
    // one's error more weight than eq. (4) does, so its error ends lower, and a smaller share of
    // the three materials' error (compared with the bright one alone the shares are within
    // the few-epoch training's noise: they flip with the backend's rounding).
    let dark = MerlTable::from_fn(|h, d, _| {
        let v = 0.004 + 0.0004 * (h as f32 - d as f32).abs();
        [v, 1.5 * v, 0.7 * v]
    });
    let bright = MerlTable::from_fn(|h, _, p| {
        let v = 0.3 + 0.004 * h as f32 + 0.0003 * p as f32;
        [2.0 * v, v, 0.5 * v]
    });
    let middle = MerlTable::from_fn(|_, d, _| {
        let v = 0.08 + 0.001 * d as f32;
        [v, v, v]
    });
    let tables = [&dark, &bright, &middle];
    let reference = MedianReference::from_tables(&tables).unwrap();
    let names = ["dark".into(), "bright".into(), "middle".into()];
    let set = TrainingSet::from_tables("t", &names, &tables, &reference).unwrap();
    let run = |power: f64| {
        let mut config = slice_config(40);
        if let crate::autoencoder::Architecture::Slice(s) = &mut config.model.architecture {
            s.augmentation = AugmentationConfig::new().with_image_weight_power(power);
        }
        let dir = tempfile::tempdir().unwrap();
        train(&config, &set, dir.path(), false, &Silent, &device()).unwrap().per_material_mse
    };
    let (plain, weighted) = (run(0.0), run(0.5));
    assert!(weighted[0] < plain[0], "dark: {} weighted vs {} plain", weighted[0], plain[0]);
    let share = |e: &[f64]| e[0] / e.iter().sum::<f64>();
    assert!(
        share(&weighted) < share(&plain),
        "dark's share: {weighted:?} weighted vs {plain:?} plain"
    );
}

/// The training configuration of the retired `cpu` preset as earlier versions wrote it (the
/// spectral network at k = 5).
fn retired_cpu_config() -> String {
    let mut value: serde_json::Value =
        serde_json::from_str(&TrainConfig::slice(5).to_string()).unwrap();
    value["model"]["architecture"] =
        serde_json::json!({"spectral": {"directions": 96, "hidden": 256, "he_init": true}});
    value.to_string()
}

//! Shared helpers for CLI tests: run the binary, temporary directories.
#![allow(dead_code)]

use deepbrdf_data::merl::MerlTable;
use std::path::Path;
use std::process::{Command, Output};

/// A path as a command-line argument.
pub fn s(p: &Path) -> String {
    p.display().to_string()
}

/// The `slice` preset's training at a tiny size: k = 2, a slice basis of 8 directions, 2
/// principal components, MLPs of width 8, one harmonic, no extra training BRDFs, 2 epochs in
/// batches of 2 (seconds on three synthetic materials).
pub fn tiny_train_config() -> deepbrdf_model::TrainConfig {
    use deepbrdf_model::autoencoder::{Architecture, SliceConfig};
    let layers = SliceConfig::new()
        .with_directions(8)
        .with_components(2)
        .with_hidden(Some(8))
        .with_harmonics(1)
        .with_augmentation(deepbrdf_model::augmentation::AugmentationConfig::new());
    let mut config = deepbrdf_model::TrainConfig::slice(2).with_epochs(2).with_batch_size(2);
    config.model = deepbrdf_model::AutoencoderConfig::new(2, Architecture::Slice(layers));
    config
}

/// Writes [`tiny_train_config`] to `dir/tiny.json` and returns its path.
pub fn tiny_config(dir: &Path) -> std::path::PathBuf {
    use deepbrdf_model::burn::config::Config as _;
    let path = dir.join("tiny.json");
    tiny_train_config().save(&path).expect("writing the training configuration");
    path
}

/// Trains a model with [`tiny_config`] on the materials in `data` into `dir/model` (asserting
/// that training succeeds) and returns that folder.
pub fn train_tiny(dir: &Path, data: &Path) -> std::path::PathBuf {
    let config_path = tiny_config(dir);
    let model = dir.join("model");
    let o = run_in(
        dir,
        &["train", "--config", &s(&config_path), "--data", &s(data), "--out", &s(&model)],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    model
}

/// Runs `experiments` with `args` in `cwd` (quiet), returning its output.
pub fn run_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_experiments"))
        .args(args)
        .arg("--quiet")
        .current_dir(cwd)
        .output()
        .expect("failed to spawn the experiments binary")
}

/// [`run_in`], asserting that the run succeeded (the arguments and stderr in the message).
pub fn run_ok(cwd: &Path, args: &[&str]) -> Output {
    let out = run_in(cwd, args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    out
}

/// A runner of successful commands in `cwd`: `ok(&[...])` runs `experiments` there ([`run_ok`]:
/// asserts it succeeded) and returns its output.
pub fn runner(cwd: &Path) -> impl Fn(&[&str]) -> Output + '_ {
    move |args| run_ok(cwd, args)
}

/// Runs `experiments` with `args` in `cwd` (quiet) on `threads` rayon threads.
pub fn run_on_threads(cwd: &Path, args: &[&str], threads: usize) -> Output {
    Command::new(env!("CARGO_BIN_EXE_experiments"))
        .args(args)
        .arg("--quiet")
        .env("RAYON_NUM_THREADS", threads.to_string())
        .current_dir(cwd)
        .output()
        .expect("failed to spawn the experiments binary")
}

/// Writes materials `0..n` ([`material`]) as `m{i}.binary` into a new folder `dir/data`, and
/// returns that folder.
pub fn write_data(dir: &Path, n: usize) -> std::path::PathBuf {
    let data = dir.join("data");
    std::fs::create_dir(&data).expect("creating the data folder");
    for i in 0..n {
        deepbrdf_data::merl::write_merl(&material(i), data.join(format!("m{i}.binary")))
            .expect("writing a material");
    }
    data
}

/// Runs `experiments` with `args` in a fresh temporary directory.
pub fn run(args: &[&str]) -> Output {
    let dir = tempfile::tempdir().expect("tempdir");
    run_in(dir.path(), args)
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a run failed cleanly: non-zero exit, an `error:` line, and no panic.
pub fn assert_clean_failure(o: &Output, needle: &str) {
    let err = stderr(o);
    assert!(!o.status.success(), "expected failure, got success; stderr: {err}");
    assert!(!err.contains("panicked"), "the binary panicked: {err}");
    assert!(err.contains("error:"), "no error line: {err}");
    assert!(err.contains(needle), "error does not mention '{needle}': {err}");
}

/// A synthetic material: a diffuse colour plus a specular lobe in theta_h, varying with `i`.
pub fn material(i: usize) -> MerlTable {
    let diffuse = [0.05 + 0.04 * i as f32, 0.1, 0.2 - 0.03 * i as f32];
    let width = 4.0 + 3.0 * i as f32;
    MerlTable::from_fn(|h, d, p| {
        let lobe = (1.0 + i as f32) * (-(h as f32 / width).powi(2)).exp();
        let fresnel = 1.0 + 0.01 * d as f32 + 0.001 * (p as f32 / 10.0).sin();
        diffuse.map(|c| c + lobe * fresnel)
    })
}

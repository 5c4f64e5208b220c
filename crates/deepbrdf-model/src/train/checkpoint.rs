//! Checkpoints that resume a run exactly: the network's weights, the optimizer's state and the
//! loop's position (epoch, batch, running loss, log) in one checksummed [`Container`], written
//! atomically; and the checks that a checkpoint belongs to the run that wants to continue it
//! (same configuration, same data).

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::store::RecordError;
use burn::tensor::Bytes;
use serde::{Deserialize, Serialize};

use super::log::EpochRecord;
use crate::artifact::sections::Container;
use crate::error::{ModelError, Result};

/// File name of the checkpoint inside a training directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// File name of the training configuration (JSON) inside a training directory.
pub const CONFIG_FILE: &str = "train_config.json";
const CHECKPOINT_KIND: &[u8; 8] = b"CKPT0001";

/// The training directory's checkpoint path.
pub fn checkpoint_path(out_dir: &Path) -> PathBuf {
    out_dir.join(CHECKPOINT_FILE)
}

/// The resumable state of a run besides the weights and the optimizer.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct TrainState {
    /// The run's whole configuration, as JSON.
    pub config: serde_json::Value,
    pub data_fingerprint: String,
    /// Completed epochs.
    pub epoch: usize,
    /// Next batch of the current epoch.
    pub batch: usize,
    pub loss_sum: f64,
    pub samples: usize,
    pub epoch_seconds: f64,
    pub total_seconds: f64,
    pub log: Vec<EpochRecord>,
}

impl TrainState {
    /// The state of a run that has not started.
    pub fn fresh(config: serde_json::Value, data_fingerprint: String) -> Self {
        Self {
            config,
            data_fingerprint,
            epoch: 0,
            batch: 0,
            loss_sum: 0.0,
            samples: 0,
            epoch_seconds: 0.0,
            total_seconds: 0.0,
            log: Vec::new(),
        }
    }
}

/// Writes `model`, `optim` and `state` to `path` (atomically).
pub(super) fn save<M: Module>(
    path: &Path,
    model: &M,
    optim: &ModuleOptimizer,
    state: &TrainState,
) -> Result<()> {
    let record_error = |e: RecordError| ModelError::format(path, e.to_string());
    let state_json = serde_json::to_vec(state)
        .map_err(|e| ModelError::Invalid(format!("cannot serialise the training state: {e}")))?;
    let weights = model.clone().into_record().into_bytes().map_err(record_error)?;
    let optimizer = optim.into_bytes().map_err(record_error)?;
    let sections: [(&str, &[u8]); 3] =
        [("state", &state_json), ("model", &weights), ("optimizer", &optimizer)];
    let r = Container::save_sections(path, CHECKPOINT_KIND, &sections);
    r
}

/// The saved state of the checkpoint at `path`.
pub(super) fn saved_state(path: &Path) -> Result<TrainState> {
    state_of(&Container::load(path, CHECKPOINT_KIND)?, path)
}

/// The whole configuration of the run whose checkpoint is at `path`, as JSON.
pub(crate) fn saved_run_config(path: &Path) -> Result<serde_json::Value> {
    Ok(saved_state(path)?.config)
}

/// The per-epoch log of the run whose checkpoint is at `path`, with the seconds each epoch
/// took (the CSV log leaves them out: they are not determined by the seed).
pub fn saved_log(path: &Path) -> Result<Vec<EpochRecord>> {
    Ok(saved_state(path)?.log)
}

fn state_of(c: &Container, path: &Path) -> Result<TrainState> {
    let state = c.get("state").ok_or_else(|| missing(path, "training state"))?;
    serde_json::from_slice(state)
        .map_err(|e| ModelError::format(path, format!("bad training state: {e}")))
}

fn missing(path: &Path, what: &str) -> ModelError {
    ModelError::format(path, format!("the checkpoint has no {what}"))
}

/// Loads the checkpoint at `path` into `skeleton` (a network of the run's configuration) and a
/// fresh `optim`, after checking that it was written with `config` on data `fingerprint`.
pub(super) fn load<M: Module>(
    path: &Path,
    config: &serde_json::Value,
    fingerprint: &str,
    skeleton: M,
    optim: ModuleOptimizer,
) -> Result<(M, ModuleOptimizer, TrainState)> {
    let mut c = Container::load(path, CHECKPOINT_KIND)?;
    let state = state_of(&c, path)?;
    if !json_close(&state.config, config) {
        return Err(ModelError::mismatch(
            path,
            format!(
                "the checkpoint was written with another configuration; resume with the same \
                 settings (saved in {CONFIG_FILE}: {})",
                state.config
            ),
        ));
    }
    if state.data_fingerprint != fingerprint {
        return Err(ModelError::mismatch(
            path,
            "the checkpoint was trained on other data (the data fingerprint differs)",
        ));
    }
    let record_error = |e: RecordError| ModelError::format(path, e.to_string());
    let model_bytes = c.take("model").ok_or_else(|| missing(path, "model"))?;
    let record = crate::record::float_record(model_bytes)
        .map_err(|e| ModelError::format(path, format!("the network's weights: {e}")))?;
    let model = skeleton.try_load_record(record).map_err(record_error)?;
    let optim_bytes = c.take("optimizer").ok_or_else(|| missing(path, "optimizer"))?;
    let optim = optim.from_bytes(Bytes::from_bytes_vec(optim_bytes)).map_err(record_error)?;
    Ok((model, optim, state))
}

/// Whether two JSON values are equal, numbers up to a relative 1e-9 (a number printed and
/// parsed again by serde_json may come back one unit in the last place away).
pub fn json_close(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => x == y || (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| json_close(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| json_close(v, w)))
        }
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use super::json_close;
    use serde_json::json;

    #[test]
    fn configurations_compare_up_to_float_round_off() {
        let a = json!({"lr": 1e-3, "beta": 0.8999999761581421, "layers": [1, 2], "name": "cpu"});
        let b = json!({"lr": 1.0000000000000002e-3, "beta": 0.8999999761581421, "layers": [1, 2], "name": "cpu"});
        assert!(json_close(&a, &b));
        for c in [
            json!({"lr": 1.1e-3, "beta": 0.8999999761581421, "layers": [1, 2], "name": "cpu"}),
            json!({"lr": 1e-3, "beta": 0.8999999761581421, "layers": [1, 3], "name": "cpu"}),
            json!({"lr": 1e-3, "beta": 0.8999999761581421, "layers": [1, 2], "name": "paper"}),
            json!({"lr": 1e-3, "beta": 0.8999999761581421, "layers": [1, 2]}),
        ] {
            assert!(!json_close(&a, &c), "{c}");
        }
    }
}

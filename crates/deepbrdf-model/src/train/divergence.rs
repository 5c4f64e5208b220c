//! The NaN stop: a batch whose loss is NaN or infinite ends the run before its step is applied,
//! with an error that says where, what was kept and what to try.

use std::path::Path;

use super::checkpoint::TrainState;
use crate::error::ModelError;

/// `Ok` for a finite `loss`; else the error for the batch at `state`'s position, naming the
/// last good checkpoint at `checkpoint` if one was written.
pub(super) fn check_finite(
    loss: f32,
    state: &TrainState,
    checkpoint: &Path,
    learning_rate: f64,
) -> crate::error::Result<()> {
    if loss.is_finite() {
        return Ok(());
    }
    let kept = if checkpoint.exists() {
        format!(
            "the last good checkpoint ({} epochs + {} batches) is kept in {}",
            state.epoch,
            state.batch,
            checkpoint.display()
        )
    } else {
        "no checkpoint had been written yet".to_string()
    };
    Err(ModelError::NonFinite {
        loss,
        epoch: state.epoch + 1,
        batch: state.batch + 1,
        kept,
        suggested_lr: learning_rate / 10.0,
    })
}

//! What a training run reports while it works, through [`Progress`]: one phase per run counted
//! in examples, with the epoch and its running mean loss as status.

use deepbrdf_data::Progress;

use super::checkpoint::TrainState;

/// The progress of one run of `epochs` epochs over `examples` examples per epoch.
pub(super) struct RunProgress<'a> {
    progress: &'a dyn Progress,
    epochs: usize,
    started: bool,
}

impl<'a> RunProgress<'a> {
    /// Starts the phase `label` for what is left of the run at `state` (nothing when the run
    /// is finished: it is only evaluated).
    pub fn start(
        progress: &'a dyn Progress,
        label: &str,
        state: &TrainState,
        epochs: usize,
        examples: usize,
        batch_size: usize,
    ) -> Self {
        let done = state.epoch * examples + (state.batch * batch_size).min(examples);
        let remaining = (epochs * examples).saturating_sub(done) as u64;
        if remaining > 0 {
            progress.start(remaining, label);
        }
        Self { progress, epochs, started: remaining > 0 }
    }

    /// A batch of `examples` examples was applied; `state` is the position after it.
    pub fn batch_done(&self, examples: usize, state: &TrainState) {
        self.progress.advance(examples as u64);
        self.progress.status(&format!(
            "epoch {}/{} loss {:.3e}",
            state.epoch + 1,
            self.epochs,
            state.loss_sum / state.samples.max(1) as f64
        ));
    }

    /// The run ended (finished or stopped).
    pub fn finish(&mut self) {
        if std::mem::take(&mut self.started) {
            self.progress.finish();
        }
    }
}

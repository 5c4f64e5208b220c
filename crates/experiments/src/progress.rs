//! Renders library [`Progress`] with indicatif; hidden with `--quiet` or off a terminal.
use deepbrdf_data::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;

/// Progress bars on stderr, one phase at a time.
pub struct Bars {
    visible: bool,
    /// The indicatif template of each bar.
    template: &'static str,
    bar: Mutex<Option<ProgressBar>>,
}

impl Bars {
    /// Bars counting items (position of length, elapsed time).
    pub fn new(quiet: bool) -> Self {
        Self::with_template(
            quiet,
            "{msg:24} [{bar:30}] {pos}/{len} {elapsed_precise} eta {eta} {prefix}",
        )
    }

    /// Bars counting bytes (bytes of total, rate; the status names the current file).
    pub fn bytes(quiet: bool) -> Self {
        Self::with_template(
            quiet,
            "{msg:22} [{bar:30}] {bytes}/{total_bytes} {binary_bytes_per_sec} eta {eta} {prefix}",
        )
    }

    fn with_template(quiet: bool, template: &'static str) -> Self {
        let visible = !quiet && std::io::stderr().is_terminal();
        Self { visible, template, bar: Mutex::new(None) }
    }
}

impl Progress for Bars {
    fn start(&self, len: u64, message: &str) {
        let bar = ProgressBar::with_draw_target(
            Some(len),
            if self.visible { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() },
        );
        let style = ProgressStyle::with_template(self.template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message(message.to_string());
        if let Ok(mut slot) = self.bar.lock() {
            if let Some(old) = slot.replace(bar) {
                old.finish_and_clear();
            }
        }
    }

    fn advance(&self, n: u64) {
        if let Ok(slot) = self.bar.lock() {
            if let Some(bar) = slot.as_ref() {
                bar.inc(n);
            }
        }
    }

    fn status(&self, status: &str) {
        if let Ok(slot) = self.bar.lock() {
            if let Some(bar) = slot.as_ref() {
                bar.set_prefix(status.to_string());
            }
        }
    }

    fn finish(&self) {
        if let Ok(mut slot) = self.bar.lock() {
            if let Some(bar) = slot.take() {
                bar.finish_and_clear();
            }
        }
    }
}

//! Progress for long runs whose output goes to a file (`nohup ... > log`): forwards everything
//! to the inner [`Progress`] (the bars) and, when stderr is not a terminal, also prints a line
//! when a phase starts and ends and at most every `interval` while it runs.

use deepbrdf_data::Progress;
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

struct Phase {
    message: String,
    len: u64,
    pos: u64,
    status: String,
    started: Instant,
    printed: Instant,
}

/// [`Progress`] that also logs lines (see the module documentation).
pub struct ProgressLog<'a> {
    inner: &'a dyn Progress,
    enabled: bool,
    interval: Duration,
    phase: Mutex<Option<Phase>>,
}

impl<'a> ProgressLog<'a> {
    /// Logs when stderr is not a terminal (and not `quiet`).
    pub fn new(inner: &'a dyn Progress, quiet: bool, interval: Duration) -> Self {
        let enabled = !quiet && !std::io::stderr().is_terminal();
        Self { inner, enabled, interval, phase: Mutex::new(None) }
    }
}

impl Progress for ProgressLog<'_> {
    fn start(&self, len: u64, message: &str) {
        self.inner.start(len, message);
        if self.enabled {
            eprintln!("[{message}] started ({len} steps)");
            if let Ok(mut phase) = self.phase.lock() {
                let now = Instant::now();
                *phase = Some(Phase {
                    message: message.to_string(),
                    len,
                    pos: 0,
                    status: String::new(),
                    started: now,
                    printed: now,
                });
            }
        }
    }

    fn advance(&self, n: u64) {
        self.inner.advance(n);
        if !self.enabled {
            return;
        }
        if let Ok(mut guard) = self.phase.lock() {
            if let Some(p) = guard.as_mut() {
                p.pos += n;
                if p.printed.elapsed() >= self.interval {
                    p.printed = Instant::now();
                    eprintln!(
                        "[{}] {}/{} after {:.0} s {}",
                        p.message,
                        p.pos,
                        p.len,
                        p.started.elapsed().as_secs_f64(),
                        p.status
                    );
                }
            }
        }
    }

    fn status(&self, status: &str) {
        self.inner.status(status);
        if let Ok(mut guard) = self.phase.lock() {
            if let Some(p) = guard.as_mut() {
                p.status = status.to_string();
            }
        }
    }

    fn finish(&self) {
        self.inner.finish();
        if let Ok(mut guard) = self.phase.lock() {
            if let Some(p) = guard.take() {
                eprintln!(
                    "[{}] done: {}/{} in {:.1} s {}",
                    p.message,
                    p.pos,
                    p.len,
                    p.started.elapsed().as_secs_f64(),
                    p.status
                );
            }
        }
    }
}

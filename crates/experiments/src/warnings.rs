//! Warnings from the libraries (they report through the `log` facade, e.g. a corrupt table-cache
//! file that is rebuilt) printed on stderr as `warning: ...`.
use log::{Level, LevelFilter, Log, Metadata, Record};

/// Prints `log` records at warning level and above.
struct StderrWarnings;

impl Log for StderrWarnings {
    fn enabled(&self, metadata: &Metadata<'_>) -> bool {
        metadata.level() <= Level::Warn
    }

    fn log(&self, record: &Record<'_>) {
        if self.enabled(record.metadata()) {
            let level = if record.level() == Level::Error { "error" } else { "warning" };
            eprintln!("{level}: {}", record.args());
        }
    }

    fn flush(&self) {}
}

/// Installs the printer (once, at start-up; later calls do nothing).
pub fn install() {
    if log::set_logger(&StderrWarnings).is_ok() {
        log::set_max_level(LevelFilter::Warn);
    }
}

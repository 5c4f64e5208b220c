//! `experiments fetch-merl`: download the official MERL BRDF database (100 `.binary` files,
//! 34,992,012 bytes each, about 3.3 GiB), verifying each file against the bundled SHA-256 table.
//!
//! Interrupted downloads resume from `NAME.binary.part`; a final `NAME.binary` only ever holds a
//! verified file. The default source is [`MERL_BASE_URL`]; the historical location is
//! [`MERL_LEGACY_BASE_URL`] (pass it with `--base-url` if the default is unreachable). MERL
//! provides the data for research and academic use only (<https://www.merl.com/brdf/>).
use anyhow::{bail, Context};
use deepbrdf_data::fetch::{
    ChecksumTable, FetchOptions, Fetcher, MERL_BASE_URL, MERL_LEGACY_BASE_URL,
};
use deepbrdf_data::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Duration;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder that receives the `NAME.binary` files (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Folder URL of the files; NAME is fetched from BASE_URL/NAME.binary. The historical
    /// location is http://people.csail.mit.edu/wojciech/BRDFDatabase/brdfs/
    #[arg(long, default_value = MERL_BASE_URL)]
    pub base_url: String,
    /// Checksum table to verify against instead of the bundled one (TSV with the header
    /// `material<TAB>sha256<TAB>size`).
    #[arg(long)]
    pub checksums: Option<PathBuf>,
    /// Only these materials (comma-separated names, e.g. `alum-bronze,gold-paint`).
    #[arg(long, value_delimiter = ',')]
    pub materials: Option<Vec<String>>,
    /// Extra attempts after a connection failure, timeout or 5xx answer (each resumes).
    #[arg(long, default_value_t = 4)]
    pub retries: u32,
    /// Seconds to wait before the first retry; doubled for each further retry.
    #[arg(long, default_value_t = 2.0)]
    pub retry_wait: f64,
    /// Seconds allowed for connecting and for each read or write on the connection.
    #[arg(long, default_value_t = 60.0)]
    pub timeout: f64,
    /// Move an existing `NAME.binary` with the wrong content aside (to `NAME.binary.mismatch`)
    /// and download it again, instead of stopping with an error.
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args, quiet: bool) -> anyhow::Result<()> {
    let table = match &args.checksums {
        Some(path) => ChecksumTable::read(path)?,
        None => ChecksumTable::bundled_merl()?,
    };
    let entries = table.select(args.materials.as_deref())?;
    let mut options = FetchOptions::new(&args.out);
    options.base_url = args.base_url.clone();
    options.retries = args.retries;
    options.retry_wait = seconds("--retry-wait", args.retry_wait, true)?;
    options.timeout = seconds("--timeout", args.timeout, false)?;
    options.force = args.force;

    let fetcher = Fetcher::new(options);
    let bars = ByteBars::new(quiet);
    let report = fetcher
        .fetch(&entries, &bars)
        .with_context(|| format!("fetching MERL files into {}", args.out.display()))?;

    println!(
        "{}: {} downloaded, {} already present and verified, {} failed (of {})",
        args.out.display(),
        report.downloaded.len(),
        report.skipped.len(),
        report.failed.len() + report.not_attempted.len(),
        entries.len()
    );
    for aside in &report.moved_aside {
        println!("moved a mismatching file aside: {}", aside.display());
    }
    if report.is_complete() {
        return Ok(());
    }
    let mut lines: Vec<String> = report
        .failed
        .iter()
        .map(|f| {
            let message = f.error.to_string();
            // Checksum and existing-file errors already start with the material's name.
            if message.starts_with(&format!("{}: ", f.material)) {
                format!("  {message}")
            } else {
                format!("  {}: {message}", f.material)
            }
        })
        .collect();
    if !report.not_attempted.is_empty() {
        lines.push(format!(
            "  not attempted after the connection failure: {} (rerun to continue; try --base-url {MERL_LEGACY_BASE_URL} if the server stays unreachable)",
            report.not_attempted.join(", ")
        ));
    }
    bail!(
        "{} of {} materials could not be fetched:\n{}",
        report.failed.len() + report.not_attempted.len(),
        entries.len(),
        lines.join("\n")
    )
}

/// A non-negative (or, with `zero_ok == false`, positive) finite number of seconds.
fn seconds(flag: &str, value: f64, zero_ok: bool) -> anyhow::Result<Duration> {
    if !value.is_finite() || value < 0.0 || (!zero_ok && value == 0.0) || value > 86_400.0 {
        bail!(
            "{flag} {value}: expected a number of seconds in {}0, 86400]",
            if zero_ok { "[" } else { "(" }
        );
    }
    Ok(Duration::from_secs_f64(value))
}

/// Progress in bytes (overall, with the current file and its MiB as the status), on stderr;
/// hidden with `--quiet` or off a terminal.
struct ByteBars {
    visible: bool,
    bar: Mutex<Option<ProgressBar>>,
}

impl ByteBars {
    fn new(quiet: bool) -> Self {
        Self { visible: !quiet && std::io::stderr().is_terminal(), bar: Mutex::new(None) }
    }
}

impl Progress for ByteBars {
    fn start(&self, len: u64, message: &str) {
        let target =
            if self.visible { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        let bar = ProgressBar::with_draw_target(Some(len), target);
        let style = ProgressStyle::with_template(
            "{msg:22} [{bar:30}] {bytes}/{total_bytes} {binary_bytes_per_sec} eta {eta} {prefix}",
        )
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

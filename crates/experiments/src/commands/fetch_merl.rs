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
use std::path::PathBuf;
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
    let bars = crate::progress::Bars::bytes(quiet);
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

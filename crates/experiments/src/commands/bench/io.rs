//! `experiments bench io`: times reading and writing MERL `.binary` files (target: reading a
//! 34,992,012-byte file must take well under 0.5 s).
use anyhow::Context;
use deepbrdf_data::merl::io::FILE_BYTES;
use deepbrdf_data::{MerlTable, Progress};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of timed reads and writes.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Directory for the temporary file (default: the system's temporary directory). The
    /// benchmark measures this directory's file system.
    #[arg(long)]
    pub dir: Option<PathBuf>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let dir = match &args.dir {
        Some(d) => tempfile::tempdir_in(d),
        None => tempfile::tempdir(),
    }
    .context("creating a temporary directory for the benchmark")?;
    let path = dir.path().join("bench.binary");
    // A table with irregular values in every valid cell (not all equal, not all zero).
    let table = MerlTable::from_fn(|h, d, p| {
        let x = (h * 8100 + d * 90 + p) as f32;
        [(x * 0.37).sin().abs(), 1.0 / (1.0 + x), x * 1e-6]
    });
    let reps = args.reps as usize;
    progress.start(2 * reps as u64, "bench io");
    let mut writes = Vec::with_capacity(reps);
    let mut reads = Vec::with_capacity(reps);
    for _ in 0..reps {
        let t = Instant::now();
        table.write(&path)?;
        writes.push(t.elapsed());
        progress.advance(1);
        let t = Instant::now();
        let back = MerlTable::read(&path)?;
        reads.push(t.elapsed());
        progress.advance(1);
        anyhow::ensure!(back == table, "{}: read back a different table", path.display());
    }
    progress.finish();
    println!(
        "MERL .binary I/O, {FILE_BYTES} bytes per file, {reps} repetitions, in {}",
        dir.path().display()
    );
    println!("{:6} {:>12} {:>12} {:>12} {:>10}", "op", "median s", "min s", "max s", "MB/s");
    for (name, times) in [("read", &mut reads), ("write", &mut writes)] {
        times.sort();
        let median = times[times.len() / 2];
        let (min, max) = (times[0], times[times.len() - 1]);
        let mbps = FILE_BYTES as f64 / 1e6 / median.as_secs_f64().max(1e-9);
        println!(
            "{name:6} {:>12.4} {:>12.4} {:>12.4} {mbps:>10.0}",
            secs(median),
            secs(min),
            secs(max)
        );
    }
    Ok(())
}

fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

//! `experiments corpus`: writes a corpus of analytic materials with known parameters
//! (`deepbrdf_data::corpus`): the parameter file `DIR/corpus.jsonl` (seed, count, one
//! JSON record a material; tables are regenerated from it bit for bit) and, with `--tables K`,
//! the first K materials tabulated as MERL `.binary` files under `DIR/tables`. Prints the file's
//! size per material and the tabulation speed on this machine. Existing files are replaced only
//! with `--force`.
use anyhow::{bail, Context};
use deepbrdf_data::corpus::{tabulate_each, write_corpus, CorpusReader, Record};
use deepbrdf_data::lock::FolderLock;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Largest `--count` (a corpus file of about 5 GB).
const MAX_COUNT: u64 = 10_000_000;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of materials.
    #[arg(long, value_name = "N")]
    pub count: u64,
    /// Seed of the sampler: material i of seed S is the same on every machine.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Output folder: corpus.jsonl and, with --tables, tables/.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Also tabulate the first K materials to DIR/tables/<index>-<family>.binary (17.5 MB each).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub tables: u64,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    if args.count == 0 || args.count > MAX_COUNT {
        bail!("--count {} is outside 1..={MAX_COUNT}", args.count);
    }
    if args.tables > args.count {
        bail!("--tables {} is more than --count {}", args.tables, args.count);
    }
    if args.out.exists() && !args.out.is_dir() {
        bail!("{}: exists and is not a directory", args.out.display());
    }
    // Creates the folder; held until the end: a second run on the same folder is refused.
    let _lock = FolderLock::acquire(&args.out)?;
    let corpus = args.out.join("corpus.jsonl");
    let tables = args.out.join("tables");
    let table_paths: Vec<PathBuf> =
        (0..args.tables).map(|i| tables.join(table_name(&Record::sampled(args.seed, i)))).collect();
    if !args.force {
        if let Some(p) = std::iter::once(&corpus).chain(&table_paths).find(|p| p.exists()) {
            bail!("{}: exists; not overwriting it (pass --force to replace it)", p.display());
        }
    }

    let start = Instant::now();
    let bytes = write_corpus(&corpus, args.seed, args.count, progress)?;
    println!(
        "{} materials (seed {}) -> {}: {} bytes, {} bytes per material, sampled in {:.2} s",
        args.count,
        args.seed,
        corpus.display(),
        bytes,
        bytes / args.count,
        start.elapsed().as_secs_f64()
    );
    if args.tables > 0 {
        write_tables(&corpus, &tables, args.tables, progress)?;
    }
    Ok(())
}

/// `<index>-<family>.binary`, the index zero-padded to 6 digits.
fn table_name(record: &Record) -> String {
    format!("{:06}-{}.binary", record.index, record.material.family)
}

/// Tabulates the first `k` records of the corpus file (read back, as a consumer would) into
/// `dir` and prints the speed.
fn write_tables(corpus: &Path, dir: &Path, k: u64, progress: &dyn Progress) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let records = CorpusReader::open(corpus)?.take(k as usize);
    let threads = rayon::current_num_threads();
    let mut writing = Duration::ZERO;
    let start = Instant::now();
    progress.start(k, "tabulating");
    let done = tabulate_each(records, threads, progress, |record, table| {
        let t = Instant::now();
        write_merl(&table, dir.join(table_name(record)))?;
        writing += t.elapsed();
        Ok(())
    });
    progress.finish();
    let done = done?;
    let tabulating = start.elapsed().saturating_sub(writing).as_secs_f64();
    println!(
        "{done} tables -> {}: tabulated at {:.2} materials per second on {threads} threads \
         ({tabulating:.2} s; writing the files took {:.2} s more)",
        dir.display(),
        done as f64 / tabulating.max(1e-9),
        writing.as_secs_f64()
    );
    Ok(())
}

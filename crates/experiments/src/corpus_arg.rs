//! `--corpus FILE [--corpus-count N]`: analytic corpus materials (`experiments corpus`,
//! `deepbrdf_data::corpus`) that train beside a dataset (`train`, `train-regressor`), tabulated
//! on the MERL grid as they are read, in parallel batches. The tables are held in memory with
//! the dataset's (17.5 MB each), so N is bounded by the memory at hand.
use anyhow::Context;
use deepbrdf_data::corpus::{tabulate_each, CorpusReader};
use deepbrdf_data::dataset::Dataset;
use deepbrdf_data::merl::VALUES;
use deepbrdf_data::Progress;
use std::path::PathBuf;

/// Materials tabulated at a time.
const BATCH: usize = 8;

#[derive(Debug, Clone, Default, clap::Args)]
pub struct CorpusArg {
    /// A corpus file (written by `experiments corpus`) whose materials train beside the data,
    /// named `corpus/INDEX-FAMILY`.
    #[arg(long, value_name = "FILE")]
    pub corpus: Option<PathBuf>,
    /// Only the first N materials of the corpus [default: all of them].
    #[arg(long, value_name = "N", requires = "corpus")]
    pub corpus_count: Option<u64>,
}

impl CorpusArg {
    /// Appends the corpus' materials (if any) to `data`, its label extended with
    /// `+corpus(N of FILE)` (the file's name). Returns how many were added.
    pub fn add_to(&self, data: &mut Dataset, progress: &dyn Progress) -> anyhow::Result<u64> {
        let Some(path) = &self.corpus else { return Ok(0) };
        let reader = CorpusReader::open(path)?;
        let total = reader.header().count;
        let count = self.corpus_count.map_or(total, |n| n.min(total));
        let gib = (count as f64) * (VALUES * 4) as f64 / (1u64 << 30) as f64;
        eprintln!(
            "adding {count} of the {total} corpus materials of {} ({gib:.1} GiB of tables)",
            path.display()
        );
        progress.start(count, "tabulating corpus materials");
        tabulate_each(reader.take(count as usize), BATCH, progress, |record, table| {
            data.names.push(format!("corpus/{:06}-{}", record.index, record.material.family));
            data.tables.push(table);
            Ok(())
        })
        .with_context(|| format!("reading the corpus {}", path.display()))?;
        progress.finish();
        let file = path
            .file_name()
            .map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into_owned());
        data.label = format!("{}+corpus({count} of {file})", data.label);
        Ok(count)
    }
}

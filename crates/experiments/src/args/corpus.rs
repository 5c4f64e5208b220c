//! `--corpus FILE [--corpus-count N]`: analytic corpus materials (`experiments corpus`,
//! `deepbrdf_data::corpus`) that train beside a dataset (`train`, `train-regressor`), streamed:
//! tabulated on the MERL grid in parallel batches as they are read and let go once used
//! (`deepbrdf_model::StreamedTables`), so N is bounded by time, not memory.
use anyhow::Context;
use deepbrdf_model::StreamedTables;
use std::path::PathBuf;

#[derive(Debug, Clone, Default, clap::Args)]
pub struct CorpusArg {
    /// A corpus file (written by `experiments corpus`) whose materials train beside the data,
    /// streamed (never held in memory whole), named `corpus/INDEX-FAMILY`.
    #[arg(long, value_name = "FILE")]
    pub corpus: Option<PathBuf>,
    /// Only the first N materials of the corpus [default: all of them].
    #[arg(long, value_name = "N", requires = "corpus")]
    pub corpus_count: Option<u64>,
}

impl CorpusArg {
    /// The corpus' materials as a stream, if a corpus was given.
    pub fn streamed(&self) -> anyhow::Result<Option<StreamedTables>> {
        let Some(path) = &self.corpus else { return Ok(None) };
        let streamed = StreamedTables::corpus(path, self.corpus_count)
            .with_context(|| format!("reading the corpus {}", path.display()))?;
        eprintln!("streaming {} beside the data", streamed.label());
        Ok(Some(streamed))
    }
}

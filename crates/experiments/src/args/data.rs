//! The data-selection arguments shared by commands that work on a dataset:
//! `--collection NAME` (a bundled collection, default `merl`), `--data DIR` (a folder of MERL
//! `.binary` files instead) and `--cache DIR` (where tabulated tables are kept).
use anyhow::Context;
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::cache::Cache;
use deepbrdf_data::dataset::{DataSource, Dataset};
use deepbrdf_data::table_set::StreamedDataset;
use deepbrdf_data::Progress;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, clap::Args)]
pub struct DataArgs {
    /// Bundled collection of materials: merl (100), nielsen2015 (8), rgl (51 NBRDF fits) or
    /// rgl-measured (7 real RGL measurements).
    #[arg(long, value_name = "NAME", default_value = "merl", conflicts_with = "data")]
    pub collection: Collection,
    /// Folder of MERL .binary files to use instead of a bundled collection (e.g. the real MERL
    /// database).
    #[arg(long, value_name = "DIR")]
    pub data: Option<PathBuf>,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// `--cache DIR`, for commands that tabulate bundled materials.
#[derive(Debug, Clone, clap::Args)]
pub struct CacheArg {
    /// Cache directory for tabulated bundled materials
    /// [default: $DEEPBRDF_CACHE, else the platform cache directory + deepbrdf].
    #[arg(long = "cache", value_name = "DIR")]
    pub dir: Option<PathBuf>,
}

impl CacheArg {
    /// The cache this argument selects.
    pub fn cache(&self) -> Cache {
        cache_at(self.dir.as_deref())
    }
}

/// The cache in `dir`, or the default location.
pub fn cache_at(dir: Option<&Path>) -> Cache {
    match dir {
        Some(d) => Cache::at(d),
        None => Cache::default_location(),
    }
}

// The training and baseline commands flatten `DataArgs`; until they land nothing here calls it.
#[allow(dead_code)]
impl DataArgs {
    /// Where the data come from.
    pub fn source(&self) -> DataSource {
        match &self.data {
            Some(dir) => DataSource::Folder(dir.clone()),
            None => DataSource::Bundled(self.collection),
        }
    }

    /// The cache of tabulated tables.
    pub fn cache(&self) -> Cache {
        self.cache.cache()
    }

    /// The selected dataset with its tables streamed (from the cache, or its files) where
    /// they can be, else loaded ([`StreamedDataset::load`]).
    pub fn load_streamed(&self, progress: &dyn Progress) -> anyhow::Result<StreamedDataset> {
        let source = self.source();
        StreamedDataset::load(&source, &self.cache(), progress)
            .with_context(|| format!("loading the dataset {}", source.label()))
    }

    /// Loads the selected dataset.
    pub fn load(&self, progress: &dyn Progress) -> anyhow::Result<Dataset> {
        let source = self.source();
        Dataset::load(&source, &self.cache(), progress)
            .with_context(|| format!("loading the dataset {}", source.label()))
    }
}

/// Loads bundled `collections` (through the cache of `data`) as one evaluation set. Names are
/// kept as they are unless two collections share one, which is then prefixed `collection/`.
pub fn load_collections(
    collections: &[Collection],
    data: &DataArgs,
    progress: &dyn Progress,
) -> anyhow::Result<Dataset> {
    if collections.is_empty() {
        anyhow::bail!("generalize mode needs at least one evaluation collection");
    }
    let cache = cache_at(data.cache.dir.as_deref());
    let mut sets = Vec::new();
    for &c in collections {
        let set = Dataset::load(&DataSource::Bundled(c), &cache, progress)
            .with_context(|| format!("loading the evaluation collection {c}"))?;
        sets.push((c, set));
    }
    let mut names: Vec<String> = Vec::new();
    let mut tables = Vec::new();
    for (c, set) in &sets {
        for (name, table) in set.names.iter().zip(&set.tables) {
            let clash = sets.iter().any(|(o, s)| o != c && s.names.contains(name));
            names.push(if clash { format!("{c}/{name}") } else { name.clone() });
            tables.push(table.clone());
        }
    }
    let label = collections.iter().map(|c| c.name()).collect::<Vec<_>>().join(" + ");
    Ok(Dataset { label, names, tables })
}

/// Loads bundled `collections` (through `cache`) as extra training materials, each named
/// `COLLECTION/NAME` (`train --add-collections`, `baselines --add-collections`, and
/// `figures-generalize` fitting IPCA on what such a model saw); the label joins the
/// collections' names with `+`.
pub fn load_added(
    collections: &[Collection],
    cache: &Cache,
    progress: &dyn Progress,
) -> anyhow::Result<Dataset> {
    let mut added = Dataset { label: String::new(), names: Vec::new(), tables: Vec::new() };
    for &collection in collections {
        let more = Dataset::load(&DataSource::Bundled(collection), cache, progress)
            .with_context(|| format!("loading the collection {}", collection.name()))?;
        added.names.extend(more.names.iter().map(|n| format!("{}/{n}", collection.name())));
        added.tables.extend(more.tables);
    }
    added.label = collections.iter().map(|c| c.name()).collect::<Vec<_>>().join("+");
    Ok(added)
}

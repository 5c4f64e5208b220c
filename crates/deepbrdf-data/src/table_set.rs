//! The tables of a run as a numbered set that hands out one table at a time ([`TableSet`]):
//! tables held in memory (a `Vec<MerlTable>`), or [`StreamedTables`], which keeps only where
//! each table comes from and reads it (from the table cache, or its MERL file) when asked for;
//! [`StreamedDataset`] is a dataset with its tables streamed. A run over
//! 100 `merl` materials holds 1.75 GB of tables in memory; streamed, it holds the few it works
//! on (users run the sweeps on laptops).

use crate::bundled::Collection;
use crate::cache::Cache;
use crate::dataset::{binary_files, material_name, DataSource, Dataset};
use crate::error::{DataError, Result};
use crate::merl::{io::read_merl, MerlTable};
use crate::nbrdf::Network;
use crate::progress::Progress;
use rayon::prelude::*;
use std::borrow::{Borrow, Cow};
use std::path::{Path, PathBuf};

/// Numbered tables, each handed out on request (borrowed when held in memory, else read).
pub trait TableSet: Sync {
    /// Number of tables.
    fn len(&self) -> usize;

    /// Whether the set has no table.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Table `i` (`i < len()`).
    fn table(&self, i: usize) -> Result<Cow<'_, MerlTable>>;
}

/// Tables in memory (`Vec<MerlTable>`, or `Vec<&MerlTable>`), lent out.
impl<T: Borrow<MerlTable> + Sync> TableSet for Vec<T> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn table(&self, i: usize) -> Result<Cow<'_, MerlTable>> {
        let table = self.get(i).ok_or_else(|| out_of_range(i, self.as_slice().len()))?;
        Ok(Cow::Borrowed(table.borrow()))
    }
}

/// Two sets one after the other: tables `0..first.len()` are `first`'s, the rest `second`'s
/// (a collection scored and the collections that only train beside it).
pub struct Concatenated<'a> {
    pub first: &'a dyn TableSet,
    pub second: &'a dyn TableSet,
}

impl TableSet for Concatenated<'_> {
    fn len(&self) -> usize {
        self.first.len() + self.second.len()
    }

    fn table(&self, i: usize) -> Result<Cow<'_, MerlTable>> {
        match i.checked_sub(self.first.len()) {
            None => self.first.table(i),
            Some(j) if j < self.second.len() => self.second.table(j),
            Some(_) => Err(out_of_range(i, self.len())),
        }
    }
}

fn out_of_range(i: usize, len: usize) -> DataError {
    DataError::Invalid(format!("table {i} requested from a set of {len}"))
}

/// Where [`StreamedTables`] reads its tables from.
enum Source {
    /// NBRDF networks, tabulated through the table cache.
    Cached { networks: Vec<&'static Network>, cache: Cache },
    /// MERL `.binary` files, read (and converted to f32) on each request.
    Files(Vec<PathBuf>),
}

/// Tables read one at a time when asked for: from the table cache (a bundled NBRDF collection)
/// or from MERL `.binary` files (a folder). Each table is the one [`Dataset::load`] gives, bit
/// for bit (the cache stores the f32 values exactly; a file is converted the same way).
pub struct StreamedTables {
    source: Source,
}

impl StreamedTables {
    /// The tables of `collection` through `cache`: every material is tabulated into the cache
    /// first (as loading the collection does) and only the networks are kept; a request reads
    /// the cache file (17.5 MB), tabulating again only if the file has gone. `None`
    /// where the tables cannot be streamed (the measured collection, converted from bundled
    /// files; a disabled cache, or one that did not store a table): load them in memory then.
    pub fn bundled(
        collection: Collection,
        cache: &Cache,
        progress: &dyn Progress,
    ) -> Result<Option<Self>> {
        if collection.is_measured() || cache.dir().is_none() {
            return Ok(None);
        }
        let networks: Vec<&'static Network> = collection.materials()?.iter().collect();
        progress.start(networks.len() as u64, &format!("tabulating {collection}"));
        let stored = networks
            .par_iter()
            .map(|net| {
                let table = cache.tabulated(net);
                progress.advance(1);
                table.map(|_| cache.path_for(net).is_some_and(|p| p.is_file()))
            })
            .collect::<Result<Vec<bool>>>();
        progress.finish();
        if !stored?.into_iter().all(|s| s) {
            return Ok(None);
        }
        Ok(Some(Self { source: Source::Cached { networks, cache: cache.clone() } }))
    }

    /// The `*.binary` files of `dir` (sorted by name, as [`Dataset::load`] reads them), each
    /// read when asked for. Every file is read once here, so a bad one is reported now.
    pub fn folder(dir: &Path, progress: &dyn Progress) -> Result<Self> {
        let paths = binary_files(dir)?;
        progress.start(paths.len() as u64, "checking MERL files");
        let checked = paths
            .par_iter()
            .with_max_len(1)
            .map(|path| {
                let table = read_merl(path).map(drop);
                progress.advance(1);
                table
            })
            .collect::<Result<Vec<()>>>();
        progress.finish();
        checked?;
        Ok(Self { source: Source::Files(paths) })
    }

    /// The material names, in table order (as [`Dataset::load`] names them).
    pub fn names(&self) -> Vec<String> {
        match &self.source {
            Source::Cached { networks, .. } => {
                networks.iter().map(|n| n.name().to_string()).collect()
            }
            Source::Files(paths) => paths.iter().map(|p| material_name(p)).collect(),
        }
    }

    /// Keeps the first `n` tables.
    pub fn truncate(&mut self, n: usize) {
        match &mut self.source {
            Source::Cached { networks, .. } => networks.truncate(n),
            Source::Files(paths) => paths.truncate(n),
        }
    }
}

impl TableSet for StreamedTables {
    fn len(&self) -> usize {
        match &self.source {
            Source::Cached { networks, .. } => networks.len(),
            Source::Files(paths) => paths.len(),
        }
    }

    fn table(&self, i: usize) -> Result<Cow<'_, MerlTable>> {
        let len = self.len();
        match &self.source {
            Source::Cached { networks, cache } => {
                let net = networks.get(i).ok_or_else(|| out_of_range(i, len))?;
                cache.tabulated(net).map(Cow::Owned)
            }
            Source::Files(paths) => {
                let path = paths.get(i).ok_or_else(|| out_of_range(i, len))?;
                read_merl(path).map(Cow::Owned)
            }
        }
    }
}

/// A dataset ([`Dataset`]'s label and names) whose tables are streamed where they can be
/// ([`StreamedTables`]), else held in memory.
pub struct StreamedDataset {
    /// What the dataset is (collection name or folder).
    pub label: String,
    /// Material names, in table order.
    pub names: Vec<String>,
    tables: Tables,
}

enum Tables {
    Memory(Vec<MerlTable>),
    Streamed(StreamedTables),
}

impl StreamedDataset {
    /// The materials of `source`: a bundled NBRDF collection through `cache`, or a folder of
    /// MERL files, streamed; the measured collection (or any without a usable cache) loaded.
    pub fn load(source: &DataSource, cache: &Cache, progress: &dyn Progress) -> Result<Self> {
        let streamed = match source {
            DataSource::Bundled(collection) => {
                StreamedTables::bundled(*collection, cache, progress)?
            }
            DataSource::Folder(dir) => Some(StreamedTables::folder(dir, progress)?),
        };
        Ok(match streamed {
            Some(tables) => Self {
                label: source.label(),
                names: tables.names(),
                tables: Tables::Streamed(tables),
            },
            None => Self::from(Dataset::load(source, cache, progress)?),
        })
    }

    /// Keeps the first `n` materials.
    pub fn truncate(&mut self, n: usize) {
        self.names.truncate(n);
        match &mut self.tables {
            Tables::Memory(tables) => tables.truncate(n),
            Tables::Streamed(tables) => tables.truncate(n),
        }
    }

    /// The tables.
    pub fn tables(&self) -> &dyn TableSet {
        match &self.tables {
            Tables::Memory(tables) => tables,
            Tables::Streamed(tables) => tables,
        }
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the dataset has no material.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
}

impl From<Dataset> for StreamedDataset {
    /// A dataset already in memory.
    fn from(data: Dataset) -> Self {
        Self { label: data.label, names: data.names, tables: Tables::Memory(data.tables) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::io::write_merl;
    use crate::progress::Silent;

    #[test]
    fn streamed_tables_are_the_loaded_ones() {
        let dir = tempfile::tempdir().expect("tempdir");
        let cache = Cache::at(dir.path().join("cache"));
        let source = DataSource::Bundled(Collection::Nielsen2015);
        let mut streamed = StreamedDataset::load(&source, &cache, &Silent).expect("streamed");
        assert!(matches!(streamed.tables, Tables::Streamed(_)));
        let loaded = Dataset::load(&source, &cache, &Silent).expect("loaded");
        assert_eq!((&streamed.label, &streamed.names), (&loaded.label, &loaded.names));
        assert_eq!(streamed.tables().len(), loaded.tables.len());
        for i in [0, loaded.len() - 1] {
            assert_eq!(*streamed.tables().table(i).expect("read"), loaded.tables[i], "table {i}");
            assert_eq!(*loaded.tables.table(i).expect("lent"), loaded.tables[i]);
        }
        assert!(streamed.tables().table(loaded.len()).is_err());
        assert!(loaded.tables.table(loaded.len()).is_err());
        streamed.truncate(2);
        assert_eq!((streamed.len(), streamed.tables().len()), (2, 2));

        // A folder of MERL files streams its files in name order.
        let folder = dir.path().join("data");
        std::fs::create_dir(&folder).expect("mkdir");
        write_merl(&loaded.tables[1], folder.join("b.binary")).expect("write");
        write_merl(&loaded.tables[0], folder.join("a.binary")).expect("write");
        let files = DataSource::Folder(folder.clone());
        let streamed = StreamedDataset::load(&files, &cache, &Silent).expect("folder");
        let read = Dataset::load(&files, &cache, &Silent).expect("read");
        assert_eq!(streamed.names, ["a", "b"]);
        for i in 0..2 {
            assert_eq!(*streamed.tables().table(i).expect("read"), read.tables[i]);
        }
        std::fs::write(folder.join("c.binary"), [0u8; 10]).expect("write");
        let err = StreamedDataset::load(&files, &cache, &Silent).err().expect("bad file");
        assert!(err.to_string().contains("c.binary"), "{err}");

        // Nothing to stream from: no cache, or a measured collection; held in memory then.
        assert!(StreamedTables::bundled(Collection::Nielsen2015, &Cache::disabled(), &Silent)
            .expect("no cache")
            .is_none());
        assert!(StreamedTables::bundled(Collection::RglMeasured, &cache, &Silent)
            .expect("measured")
            .is_none());
    }

    #[test]
    fn concatenated_sets_hand_out_both_in_order() {
        let (_, tables) = crate::testing::sparse_set(3);
        let first = vec![&tables[0]];
        let second = vec![&tables[1], &tables[2]];
        let both = Concatenated { first: &first, second: &second };
        assert_eq!(both.len(), 3);
        for (i, table) in tables.iter().enumerate() {
            assert_eq!(*both.table(i).expect("in range"), *table, "table {i}");
        }
        let err = both.table(3).unwrap_err().to_string();
        assert!(err.contains("table 3 requested from a set of 3"), "{err}");
    }
}

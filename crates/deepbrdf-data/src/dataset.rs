//! A dataset: a named set of measured materials as MERL tables in memory (f32, 1/sr), from a
//! bundled NBRDF collection (tabulated, through the [`Cache`]) or from a folder of MERL `.binary`
//! files (the real MERL database, §3.1 of Hu et al. 2020). The default is the bundled `merl`
//! collection.

use crate::bundled::{find_material, Collection};
use crate::cache::Cache;
use crate::error::{DataError, Result};
use crate::merl::{io::read_merl, MerlTable};
use crate::progress::Progress;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Where a dataset's materials come from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DataSource {
    /// A collection of bundled NBRDF networks, tabulated onto the MERL grid.
    Bundled(Collection),
    /// Every `*.binary` MERL file in a folder, sorted by file name.
    Folder(PathBuf),
}

impl Default for DataSource {
    fn default() -> Self {
        DataSource::Bundled(Collection::Merl)
    }
}

impl DataSource {
    /// A short label: the collection name, or the folder's path.
    pub fn label(&self) -> String {
        match self {
            DataSource::Bundled(c) => c.name().to_string(),
            DataSource::Folder(dir) => dir.display().to_string(),
        }
    }
}

/// Named MERL tables held in memory as f32 (no f64 copies).
#[derive(Debug, Clone)]
pub struct Dataset {
    /// What the dataset is (collection name or folder).
    pub label: String,
    /// Material names, in the order of `tables` (sorted).
    pub names: Vec<String>,
    /// One table per material.
    pub tables: Vec<MerlTable>,
}

impl Dataset {
    /// Loads every material of `source`. Bundled collections are tabulated in parallel (or read
    /// from `cache`); folders are read file by file, in parallel.
    pub fn load(source: &DataSource, cache: &Cache, progress: &dyn Progress) -> Result<Self> {
        let (names, tables) = match source {
            DataSource::Bundled(collection) => load_bundled(*collection, cache, progress)?,
            DataSource::Folder(dir) => load_folder(dir, progress)?,
        };
        Ok(Self { label: source.label(), names, tables })
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.tables.len()
    }

    /// Whether the dataset has no material (never true for a loaded dataset).
    pub fn is_empty(&self) -> bool {
        self.tables.is_empty()
    }

    /// The table of the material called `name`.
    pub fn get(&self, name: &str) -> Option<&MerlTable> {
        self.names.iter().position(|n| n == name).map(|i| &self.tables[i])
    }
}

fn load_bundled(
    collection: Collection,
    cache: &Cache,
    progress: &dyn Progress,
) -> Result<(Vec<String>, Vec<MerlTable>)> {
    if collection.is_measured() {
        return load_measured(cache, progress);
    }
    let networks = collection.materials()?;
    progress.start(networks.len() as u64, &format!("tabulating {collection}"));
    let tables = networks
        .par_iter()
        .map(|net| {
            let table = cache.tabulated(net);
            progress.advance(1);
            table
        })
        .collect::<Result<Vec<_>>>();
    progress.finish();
    Ok((networks.iter().map(|n| n.name().to_string()).collect(), tables?))
}

/// The bundled RGL measurements, converted to the MERL grid (cached).
fn load_measured(cache: &Cache, progress: &dyn Progress) -> Result<(Vec<String>, Vec<MerlTable>)> {
    let names = crate::rgl::bundled::names();
    progress.start(names.len() as u64, "converting rgl-measured");
    let tables = names
        .iter()
        .map(|name| {
            let table = load_measured_material(name, cache);
            progress.advance(1);
            table
        })
        .collect::<Result<Vec<_>>>();
    progress.finish();
    Ok((names.iter().map(|n| n.to_string()).collect(), tables?))
}

/// The bundled measurement `name`, converted to the MERL grid (cached).
fn load_measured_material(name: &str, cache: &Cache) -> Result<MerlTable> {
    let bytes = crate::rgl::bundled::bytes(name)?;
    Ok(cache.converted(name, &crate::rgl::bundled::origin(name), &bytes)?.0)
}

/// An RGL `.bsdf` file converted to the MERL grid (cached under the file's stem).
fn load_bsdf_file(path: &Path, cache: &Cache) -> Result<MerlTable> {
    let (mut file, len) = crate::files::open_regular(path)?;
    if len > crate::rgl::tensor::MAX_FILE_BYTES {
        return Err(DataError::format(path, format!("{len} bytes: too large for a tensor file")));
    }
    let bytes = crate::files::read_exactly(&mut file, path, len as usize)?;
    Ok(cache.converted(&material_name(path), path, &bytes)?.0)
}

/// The `*.binary` files of `dir`, sorted by file name. Errors for a missing or empty directory.
pub fn binary_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let meta = std::fs::metadata(dir).map_err(|e| DataError::io(dir, e))?;
    if !meta.is_dir() {
        return Err(DataError::format(dir, "is not a directory of MERL .binary files"));
    }
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| DataError::io(dir, e))? {
        let path = entry.map_err(|e| DataError::io(dir, e))?.path();
        if path.extension().is_some_and(|e| e == "binary") && !path.is_dir() {
            paths.push(path);
        }
    }
    if paths.is_empty() {
        return Err(DataError::format(dir, "contains no MERL .binary files"));
    }
    paths.sort();
    Ok(paths)
}

fn load_folder(dir: &Path, progress: &dyn Progress) -> Result<(Vec<String>, Vec<MerlTable>)> {
    let paths = binary_files(dir)?;
    progress.start(paths.len() as u64, "reading MERL files");
    // One file per task: each holds its 35 MB of f64 only while converting it to f32.
    let tables = paths
        .par_iter()
        .with_max_len(1)
        .map(|path| {
            let table = read_merl(path);
            progress.advance(1);
            table
        })
        .collect::<Result<Vec<_>>>();
    progress.finish();
    let names = paths.iter().map(|p| material_name(p)).collect();
    Ok((names, tables?))
}

/// A material's name from its file: the file stem (`chrome.binary` -> `chrome`).
pub(crate) fn material_name(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// Whether `spec` names a file rather than a bundled material: it ends in `.binary`, is an
/// existing file, or is a path that is not of the form `collection/name`.
fn is_file_spec(spec: &str) -> bool {
    if spec.ends_with(".binary") || Path::new(spec).is_file() {
        return true;
    }
    match spec.split_once('/') {
        None => spec.contains(std::path::MAIN_SEPARATOR),
        Some((col, name)) => col.parse::<Collection>().is_err() || name.contains('/'),
    }
}

/// Loads one material: `spec` is a MERL `.binary` path, an RGL `.bsdf` path (converted to the
/// MERL grid and cached), or a bundled material name (`chrome`, `merl/chrome`,
/// `rgl/cardboard_rgb`, `rgl-measured/paper_white_rgb`). Returns the material's name and its
/// table. Unknown names give an error listing close matches.
pub fn load_material(spec: &str, cache: &Cache) -> Result<(String, MerlTable)> {
    if spec.starts_with("rgl-measured/") {
        return load_bundled_material(spec, cache);
    }
    if spec.ends_with(".bsdf") {
        let path = Path::new(spec);
        return Ok((material_name(path), load_bsdf_file(path, cache)?));
    }
    if is_file_spec(spec) {
        let path = Path::new(spec);
        return Ok((material_name(path), read_merl(path)?));
    }
    load_bundled_material(spec, cache)
}

/// Loads a bundled material by name only (`chrome`, `merl/chrome`,
/// `rgl-measured/paper_white_rgb`): never a file, whatever the working directory holds (the
/// browser editor's materials). Returns the material's name and its table.
pub fn load_bundled_material(spec: &str, cache: &Cache) -> Result<(String, MerlTable)> {
    if let Some(name) = spec.strip_prefix("rgl-measured/") {
        return Ok((name.to_string(), load_measured_material(name, cache)?));
    }
    let (_, net) = find_material(spec)?;
    Ok((net.name().to_string(), cache.tabulated(net)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::io::write_merl;
    use crate::progress::Silent;

    #[test]
    fn folder_errors_name_the_folder_or_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let missing = dir.path().join("missing");
        let err = Dataset::load(&DataSource::Folder(missing.clone()), &Cache::disabled(), &Silent)
            .expect_err("missing");
        assert!(err.to_string().contains("missing"), "{err}");

        std::fs::write(dir.path().join("notes.txt"), "x").expect("write");
        let err =
            Dataset::load(&DataSource::Folder(dir.path().into()), &Cache::disabled(), &Silent)
                .expect_err("empty");
        assert!(err.to_string().contains("contains no MERL .binary files"), "{err}");

        let bad = dir.path().join("bad.binary");
        std::fs::write(&bad, [0u8; 100]).expect("write");
        let err =
            Dataset::load(&DataSource::Folder(dir.path().into()), &Cache::disabled(), &Silent)
                .expect_err("bad file");
        assert!(err.to_string().contains("bad.binary"), "{err}");

        let file = DataSource::Folder(dir.path().join("notes.txt"));
        assert!(Dataset::load(&file, &Cache::disabled(), &Silent).is_err());
    }

    #[test]
    fn folder_is_read_sorted_and_materials_load_by_path_or_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        let cache = Cache::at(dir.path().join("cache"));
        let (name, chrome) = load_material("merl/chrome", &cache).expect("bundled");
        assert_eq!(name, "chrome");
        assert!(chrome.valid_cells() > 1_000_000);
        let (_, again) = load_material("chrome", &cache).expect("cached");
        assert_eq!(again, chrome);
        let folder = dir.path().join("data");
        std::fs::create_dir(&folder).expect("mkdir");
        write_merl(&chrome, folder.join("b-chrome.binary")).expect("write");
        let lambert = MerlTable::from_fn(|_, _, _| [0.2, 0.3, 0.1]);
        write_merl(&lambert, folder.join("a-lambert.binary")).expect("write");
        let data =
            Dataset::load(&DataSource::Folder(folder.clone()), &cache, &Silent).expect("load");
        assert_eq!(data.names, ["a-lambert", "b-chrome"]);
        assert_eq!(data.len(), 2);
        assert_eq!(data.get("b-chrome"), Some(&chrome));
        assert_eq!(data.get("a-lambert").map(|t| t.rgb(0, 0, 0)), Some([0.2, 0.3, 0.1]));

        let path = folder.join("b-chrome.binary");
        let (name, table) = load_material(path.to_str().expect("utf8"), &cache).expect("file");
        assert_eq!((name.as_str(), &table), ("b-chrome", &chrome));
        let err = load_material("chrom", &cache).expect_err("unknown").to_string();
        assert!(err.contains("merl/chrome"), "{err}");
        let err = load_material("nowhere/x.binary", &cache).expect_err("missing").to_string();
        assert!(err.contains("nowhere/x.binary"), "{err}");
    }
}

//! On-disk cache of tabulated tables (NBRDF networks, and RGL measurements converted to the MERL
//! grid), so each material is tabulated once.
//!
//! One file per material, `<dir>/tables/<name>-<key>.tab`, where `<key>` starts the hex
//! SHA-256 of the network's parameters and [`TABULATOR_VERSION`] (of an RGL file's bytes and
//! [`RGL_TABULATOR_VERSION`]): a changed network, file or tabulator gives a new key, so stale
//! tables are never read (and are pruned when replaced).
//! Files are written to a temporary name and renamed into place. Reading checks the size, the
//! header (magic, versions, key) and a checksum of the values before trusting anything
//! ([`file`]); a corrupt, truncated or foreign file is recomputed and replaced, with a warning.

mod file;

use crate::error::Result;
use crate::files::create_parent_and_write;
use crate::merl::MerlTable;
use crate::nbrdf::{tabulate, Network, TABULATOR_VERSION};
use crate::rgl::{RglBrdf, RGL_TABULATOR_VERSION};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Environment variable that overrides the default cache directory.
pub const CACHE_ENV: &str = "DEEPBRDF_CACHE";
/// Hex digits of the key used in file names.
const KEY_DIGITS: usize = 16;

/// Where a table came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Read from a valid cache file.
    Hit,
    /// Tabulated: there was no cache file (or caching is disabled).
    Computed,
    /// Tabulated because the cache file was corrupt, truncated or foreign (and rebuilt, with a
    /// `log` warning naming the file and the problem).
    Recomputed,
}

/// The table cache: a directory, or disabled (always tabulate, write nothing).
#[derive(Debug, Clone)]
pub struct Cache {
    dir: Option<PathBuf>,
}

impl Cache {
    /// A cache in `dir` (created on first write).
    pub fn at(dir: impl Into<PathBuf>) -> Self {
        Self { dir: Some(dir.into()) }
    }

    /// No caching: tables are tabulated on every request.
    pub fn disabled() -> Self {
        Self { dir: None }
    }

    /// The default cache: `$DEEPBRDF_CACHE` if set and non-empty, else the platform's cache
    /// directory + `deepbrdf` (e.g. `~/.cache/deepbrdf`); disabled if neither exists.
    pub fn default_location() -> Self {
        match std::env::var_os(CACHE_ENV).filter(|v| !v.is_empty()) {
            Some(dir) => Self::at(dir),
            None => Self { dir: dirs::cache_dir().map(|d| d.join("deepbrdf")) },
        }
    }

    /// The cache directory, if caching is enabled.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    /// The cache key of `net`: SHA-256 over the tabulator version and the network's parameters.
    pub fn key(net: &Network) -> [u8; 32] {
        let mut h = Sha256::new();
        h.update(b"deepbrdf nbrdf table");
        h.update(TABULATOR_VERSION.to_le_bytes());
        h.update(net.parameter_bytes());
        h.finalize().into()
    }

    /// The cache file of `net`, if caching is enabled.
    pub fn path_for(&self, net: &Network) -> Option<PathBuf> {
        self.path_of(net.name(), &Self::key(net))
    }

    /// The tabulated table of `net`, from the cache when a valid file exists, else tabulated and
    /// stored.
    pub fn tabulated(&self, net: &Network) -> Result<MerlTable> {
        self.tabulated_with_outcome(net).map(|(table, _)| table)
    }

    /// Like [`Cache::tabulated`], also saying whether the cache was used.
    pub fn tabulated_with_outcome(&self, net: &Network) -> Result<(MerlTable, Outcome)> {
        self.cached(net.name(), &Self::key(net), TABULATOR_VERSION, || tabulate(net))
    }

    /// The cache key of an RGL measurement: SHA-256 over the RGL tabulator version and the
    /// `.bsdf` file's bytes.
    pub fn rgl_key(bytes: &[u8]) -> [u8; 32] {
        let mut h = Sha256::new();
        h.update(b"deepbrdf rgl table");
        h.update(RGL_TABULATOR_VERSION.to_le_bytes());
        h.update(TABULATOR_VERSION.to_le_bytes());
        h.update(bytes);
        h.finalize().into()
    }

    /// The MERL table of the RGL measurement called `name` whose `.bsdf` file has `bytes`
    /// (`origin` names it in errors): from the cache when a valid file exists, else parsed,
    /// converted ([`crate::rgl::tabulate`]) and stored.
    pub fn converted(
        &self,
        name: &str,
        origin: &Path,
        bytes: &[u8],
    ) -> Result<(MerlTable, Outcome)> {
        let key = Self::rgl_key(bytes);
        self.cached(name, &key, RGL_TABULATOR_VERSION, || {
            crate::rgl::tabulate(&RglBrdf::parse(origin, bytes)?)
        })
    }

    /// The cache file of material `name` under `key`, if caching is enabled.
    fn path_of(&self, name: &str, key: &[u8; 32]) -> Option<PathBuf> {
        let key = hex::encode(key);
        let file = format!("{}-{}.tab", file_safe(name), &key[..KEY_DIGITS]);
        self.dir.as_ref().map(|d| d.join("tables").join(file))
    }

    /// A table from the cache file of (`name`, `key`) if valid, else from `compute` (stored).
    fn cached(
        &self,
        name: &str,
        key: &[u8; 32],
        version: u32,
        compute: impl FnOnce() -> Result<MerlTable>,
    ) -> Result<(MerlTable, Outcome)> {
        let Some(path) = self.path_of(name, key) else {
            return Ok((compute()?, Outcome::Computed));
        };
        let outcome = match file::read(&path, key, version) {
            Ok(Some(table)) => return Ok((table, Outcome::Hit)),
            Ok(None) => Outcome::Computed,
            Err(e) => {
                log::warn!("{e}: not used, tabulating the table again");
                Outcome::Recomputed
            }
        };
        let table = compute()?;
        create_parent_and_write(&path, &file::encode(key, version, &table))?;
        prune_stale(&path, name);
        Ok((table, outcome))
    }
}

/// A material name made safe as a file-name part.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect()
}

/// Removes other cache files of the same material (older keys).
fn prune_stale(current: &Path, name: &str) {
    let (Some(dir), Some(cur)) = (current.parent(), current.file_name()) else { return };
    let prefix = format!("{}-", file_safe(name));
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(f) = file.to_str() else { continue };
        let is_same_material = f
            .strip_prefix(&prefix)
            .and_then(|rest| rest.strip_suffix(".tab"))
            .is_some_and(|k| k.len() == KEY_DIGITS && k.bytes().all(|b| b.is_ascii_hexdigit()));
        if is_same_material && file != cur {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nbrdf::PARAMETERS;

    fn small_net(name: &str, scale: f32) -> Network {
        let mut params: Vec<f32> =
            (0..PARAMETERS).map(|i| ((i as f32) * 0.37).sin() * scale).collect();
        // Output biases well above 0, so the table is not clamped to all zeros.
        params[PARAMETERS - 3..].fill(1.0 + scale);
        Network::from_parameters(name, &params).expect("valid")
    }

    #[test]
    fn cache_hits_invalidates_and_recovers_from_corruption() {
        let dir = tempfile::tempdir().expect("tempdir");
        let cache = Cache::at(dir.path());
        let net = small_net("mat", 0.3);
        let (first, outcome) = cache.tabulated_with_outcome(&net).expect("tabulate");
        assert_eq!(outcome, Outcome::Computed);
        let path = cache.path_for(&net).expect("enabled");
        assert_eq!(std::fs::metadata(&path).expect("written").len(), file::FILE_BYTES as u64);
        let (again, outcome) = cache.tabulated_with_outcome(&net).expect("hit");
        assert_eq!(outcome, Outcome::Hit);
        assert_eq!(again, first);

        // Truncated file: detected, recomputed, replaced.
        let full = std::fs::read(&path).expect("read");
        std::fs::write(&path, &full[..full.len() / 2]).expect("truncate");
        let (t, outcome) = cache.tabulated_with_outcome(&net).expect("recompute");
        assert_eq!((outcome, &t), (Outcome::Recomputed, &first));
        assert_eq!(cache.tabulated_with_outcome(&net).expect("hit").1, Outcome::Hit);

        // One flipped bit in the values: caught by the checksum.
        let mut flipped = full.clone();
        flipped[file::HEADER + 12345] ^= 0x10;
        std::fs::write(&path, &flipped).expect("corrupt");
        let (t, outcome) = cache.tabulated_with_outcome(&net).expect("recompute");
        assert_eq!((outcome, &t), (Outcome::Recomputed, &first));

        // A changed network gets a new key and file; the stale one is pruned.
        let changed = small_net("mat", 0.31);
        let new_path = cache.path_for(&changed).expect("enabled");
        assert_ne!(new_path, path);
        let (t, outcome) = cache.tabulated_with_outcome(&changed).expect("tabulate");
        assert_eq!(outcome, Outcome::Computed);
        assert_ne!(t, first);
        assert!(!path.exists() && new_path.exists());

        // A file holding another network's table under this key's name is not trusted.
        std::fs::copy(&new_path, &path).expect("copy");
        assert!(file::read(&path, &Cache::key(&net), TABULATOR_VERSION).is_err());
        let leftovers: Vec<_> = std::fs::read_dir(path.parent().expect("dir"))
            .expect("list")
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
    }

    #[test]
    fn disabled_cache_writes_nothing() {
        let cache = Cache::disabled();
        let net = small_net("m", 0.2);
        assert!(cache.path_for(&net).is_none());
        assert_eq!(cache.tabulated_with_outcome(&net).expect("tabulate").1, Outcome::Computed);
    }
}

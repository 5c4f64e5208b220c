//! Crash-safe file writes: write a temporary file beside the target, flush it to disk, then
//! rename it over the target, so a reader (or a run killed mid-write) sees the old file or the
//! new one, never a mixture.

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{ModelError, Result};

/// The temporary name used while `path` is being written.
pub fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(format!(".tmp{}", std::process::id()));
    path.with_file_name(name)
}

/// Writes `parts` (concatenated) to `path` atomically.
pub fn write_atomic(path: &Path, parts: &[&[u8]]) -> Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut file = File::create(&tmp).map_err(|e| ModelError::io(&tmp, e))?;
        for part in parts {
            file.write_all(part).map_err(|e| ModelError::io(&tmp, e))?;
        }
        file.sync_all().map_err(|e| ModelError::io(&tmp, e))?;
        drop(file);
        fs::rename(&tmp, path).map_err(|e| ModelError::io(path, e))?;
        sync_parent(path);
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Flushes the directory entry of `path` (best effort: not every platform allows it).
pub fn sync_parent(path: &Path) {
    if let Some(parent) = path.parent() {
        let dir = if parent.as_os_str().is_empty() { Path::new(".") } else { parent };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
}

/// Reads a whole file, refusing ones larger than `limit` bytes (a foreign or damaged file must
/// not trigger a huge allocation).
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let meta = fs::metadata(path).map_err(|e| ModelError::io(path, e))?;
    if !meta.is_file() {
        return Err(ModelError::format(path, "not a regular file"));
    }
    if meta.len() > limit {
        return Err(ModelError::format(
            path,
            format!("{} bytes is larger than the {limit} bytes allowed", meta.len()),
        ));
    }
    fs::read(path).map_err(|e| ModelError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_target_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.bin");
        write_atomic(&path, &[b"old"]).unwrap();
        write_atomic(&path, &[b"ne", b"w"]).unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
        assert!(read_limited(&path, 2).is_err());
        assert_eq!(read_limited(&path, 3).unwrap(), b"new");
    }
}

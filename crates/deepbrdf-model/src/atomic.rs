//! Crash-safe file access of the model crate: atomic writes (through the data crate's one writer:
//! a reader, or a run killed mid-write, sees the old file or the new one, never a mixture) and
//! size-limited reads.

use std::fs;
use std::path::Path;

use crate::error::{ModelError, Result};

/// Writes `parts` (concatenated) to `path` atomically through the workspace's one writer,
/// [`deepbrdf_data::files::write_atomic_parts`] (unique temporary name, fsync, rename).
pub fn write_atomic(path: &Path, parts: &[&[u8]]) -> Result<()> {
    Ok(deepbrdf_data::files::write_atomic_parts(path, parts)?)
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

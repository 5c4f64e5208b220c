//! Careful file access shared by the binary formats of this crate: reading a whole file after
//! checking what it is, and atomic writes (temporary file in the same directory, then rename), so
//! that a crash or a full disk never leaves a half-written file under its final name (the
//! temporary files a killed writer leaves behind are removed by [`crate::lock`]).

use crate::error::{DataError, Result};
use std::fs::File;
use std::io::{Read, Write};
use std::path::Path;

/// Name prefix and suffix of [`write_atomic_parts`]' temporary files.
pub const TEMP_PREFIX: &str = ".deepbrdf-";
pub const TEMP_SUFFIX: &str = ".tmp";

/// Opens `path` for reading and returns the file with its length in bytes. A missing path or a
/// directory is an error naming the path.
pub(crate) fn open_regular(path: &Path) -> Result<(File, u64)> {
    let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, e))?;
    if meta.is_dir() {
        return Err(DataError::format(path, "is a directory, not a file"));
    }
    let file = File::open(path).map_err(|e| DataError::io(path, e))?;
    let len = file.metadata().map_err(|e| DataError::io(path, e))?.len();
    Ok((file, len))
}

/// Reads exactly `len` bytes from `file` (whose length was checked by the caller) and fails if
/// the file turns out shorter, or longer (it changed since it was checked).
pub(crate) fn read_exactly(file: &mut File, path: &Path, len: usize) -> Result<Vec<u8>> {
    let mut bytes = vec![0u8; len];
    file.read_exact(&mut bytes).map_err(|e| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            DataError::format(path, format!("truncated: fewer than {len} bytes"))
        } else {
            DataError::io(path, e)
        }
    })?;
    let mut extra = [0u8; 1];
    match file.read(&mut extra) {
        Ok(0) => Ok(bytes),
        Ok(_) => Err(DataError::format(path, format!("trailing bytes after the expected {len}"))),
        Err(e) => Err(DataError::io(path, e)),
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory is written,
/// flushed to disk and renamed over `path`. On failure `path` is untouched and the temporary file
/// is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_parts(path, &[bytes])
}

/// Creates the parent directory of `path` if needed, then writes `bytes` there atomically
/// ([`write_atomic`]).
pub fn create_parent_and_write(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
    }
    write_atomic(path, bytes)
}

/// Writes `parts`, concatenated, to `path` atomically ([`write_atomic_with`]).
pub fn write_atomic_parts(path: &Path, parts: &[&[u8]]) -> Result<()> {
    write_atomic_with(path, |out, tmp| {
        parts.iter().try_for_each(|part| out.write_all(part).map_err(|e| DataError::io(tmp, e)))
    })
}

/// Writes to `path` atomically what `write(out, temporary_path)` writes to `out` (the one atomic
/// writer of the workspace; a long output is streamed through a buffer, never held whole): a
/// uniquely named temporary file in the same directory (two runs writing the same path never
/// share it) is written, flushed to disk (fsync) and renamed over `path`, then the directory entry
/// is flushed. On failure (of `write` too) `path` is untouched and the temporary file is removed.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write, &Path) -> Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if path.is_dir() {
        return Err(DataError::format(path, "is a directory; refusing to replace it by a file"));
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(TEMP_PREFIX).suffix(TEMP_SUFFIX);
    #[cfg(unix)]
    builder.permissions(mode_for(path));
    let tmp = builder.tempfile_in(dir).map_err(|e| DataError::io(dir, e))?;
    let tmp_path = tmp.path().to_path_buf();
    let mut out = std::io::BufWriter::new(tmp);
    write(&mut out, &tmp_path)?;
    let tmp = out.into_inner().map_err(|e| DataError::io(&tmp_path, e.into_error()))?;
    tmp.as_file().sync_all().map_err(|e| DataError::io(&tmp_path, e))?;
    tmp.persist(path).map_err(|e| DataError::io(path, e.error))?;
    sync_dir_of(path);
    Ok(())
}

/// The permissions of the file written at `path`: those of the file it replaces, else
/// read-write for the owner and readable by all, less the umask (the temporary file's own
/// default, owner-only, would make every output private).
#[cfg(unix)]
fn mode_for(path: &Path) -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(path)
        .map(|m| m.permissions())
        .unwrap_or_else(|_| std::fs::Permissions::from_mode(0o644))
}

/// Flushes the directory entry of `path` to disk after a rename (best effort: not every platform
/// allows opening a directory).
pub fn sync_dir_of(path: &Path) {
    if let Some(parent) = path.parent() {
        let dir = if parent.as_os_str().is_empty() { Path::new(".") } else { parent };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    #[cfg(unix)]
    #[test]
    fn a_new_file_is_readable_by_others_and_a_replaced_one_keeps_its_mode() -> TestResult {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("out.bin");
        write_atomic(&path, b"one")?;
        let mode = std::fs::metadata(&path)?.permissions().mode() & 0o777;
        assert_eq!(mode & 0o600, 0o600, "{mode:o}");
        assert_ne!(mode, 0o600, "owner-only, as the temporary file was: {mode:o}");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640))?;
        write_atomic(&path, b"two")?;
        assert_eq!(std::fs::metadata(&path)?.permissions().mode() & 0o777, 0o640);
        assert_eq!(std::fs::read(&path)?, b"two");
        Ok(())
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() -> TestResult {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("a.bin");
        write_atomic(&path, b"first")?;
        write_atomic_parts(&path, &[b"sec", b"", b"ond"])?;
        assert_eq!(std::fs::read(&path)?, b"second");
        let names: Vec<_> =
            std::fs::read_dir(dir.path())?.filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.bin")]);
        Ok(())
    }

    #[test]
    fn write_into_missing_directory_names_it() {
        let err = write_atomic(Path::new("/nonexistent-deepbrdf-dir/x.bin"), b"x");
        let msg = err.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("/nonexistent-deepbrdf-dir"), "{msg}");
    }

    #[test]
    fn directory_and_missing_path_are_errors_naming_the_path() -> TestResult {
        let dir = tempfile::tempdir()?;
        let msg = open_regular(dir.path()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("directory") && msg.contains(&*dir.path().to_string_lossy()), "{msg}");
        let missing = dir.path().join("missing.bin");
        let msg = open_regular(&missing).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("missing.bin"), "{msg}");
        Ok(())
    }
}

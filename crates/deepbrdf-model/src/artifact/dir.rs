//! A saved network's directory of parts: found from the directory itself or the folder holding
//! it, and written into a temporary sibling that is renamed into place, so a reader (or a run
//! killed mid-save) sees the old directory or the new one, never a mixture.

use std::fs;
use std::path::{Path, PathBuf};

use deepbrdf_data::files::sync_dir_of;

use crate::error::{ModelError, Result};

/// `path` itself if it holds `manifest`, else `path/inner` if that does; else an error saying
/// that `path` is not `what` (a saved network of this crate: a model, a recovery network).
pub(crate) fn resolve(path: &Path, manifest: &str, inner: &str, what: &str) -> Result<PathBuf> {
    if path.join(manifest).is_file() {
        return Ok(path.to_path_buf());
    }
    let inner_dir = path.join(inner);
    if inner_dir.join(manifest).is_file() {
        return Ok(inner_dir);
    }
    if !path.exists() {
        return Err(ModelError::io(path, std::io::Error::from(std::io::ErrorKind::NotFound)));
    }
    Err(ModelError::format(path, format!("not {what} (no {manifest} here or in {inner}/)")))
}

/// Writes the directory `dir` with `write_parts` into a temporary sibling and renames it into
/// place. An existing `dir` is replaced only if it holds `manifest` (it is `what`).
pub(crate) fn save(
    dir: &Path,
    manifest: &str,
    what: &str,
    write_parts: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if dir.exists() && !dir.join(manifest).is_file() {
        return Err(ModelError::Invalid(format!(
            "{} exists and is not {what}; not replacing it",
            dir.display()
        )));
    }
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.with_file_name(format!(".{name}.tmp{}", std::process::id()));
    if tmp.exists() {
        fs::remove_dir_all(&tmp).map_err(|e| ModelError::io(&tmp, e))?;
    }
    fs::create_dir_all(&tmp).map_err(|e| ModelError::io(&tmp, e))?;
    let result = write_parts(&tmp).and_then(|()| replace(&tmp, dir));
    if result.is_err() {
        let _ = fs::remove_dir_all(&tmp);
    }
    result
}

/// Moves the finished directory `tmp` to `dir`, replacing an older one there.
fn replace(tmp: &Path, dir: &Path) -> Result<()> {
    if dir.exists() {
        let old = tmp.with_extension("old");
        if old.exists() {
            fs::remove_dir_all(&old).map_err(|e| ModelError::io(&old, e))?;
        }
        fs::rename(dir, &old).map_err(|e| ModelError::io(dir, e))?;
        fs::rename(tmp, dir).map_err(|e| ModelError::io(dir, e))?;
        fs::remove_dir_all(&old).map_err(|e| ModelError::io(&old, e))?;
    } else {
        fs::rename(tmp, dir).map_err(|e| ModelError::io(dir, e))?;
    }
    sync_dir_of(dir);
    Ok(())
}

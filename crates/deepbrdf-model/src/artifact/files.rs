//! Crash-safe file access of the model crate: atomic writes (through the data crate's one writer:
//! a reader, or a run killed mid-write, sees the old file or the new one, never a mixture),
//! size-limited reads, the weights files of saved networks (written packed, read in either
//! form), and the manifests every saved network carries (written as pretty JSON, their format
//! and version checked on reading).

use std::fs;
use std::ops::RangeInclusive;
use std::path::Path;

use deepbrdf_data::packed::{self, Arrangement};
use serde::Serialize;

use crate::error::{ModelError, Result};

/// Writes `parts` (concatenated) to `path` atomically through the workspace's one writer,
/// [`deepbrdf_data::files::write_atomic_parts`] (unique temporary name, fsync, rename).
pub fn write_atomic(path: &Path, parts: &[&[u8]]) -> Result<()> {
    Ok(deepbrdf_data::files::write_atomic_parts(path, parts)?)
}

/// Writes a network's `weights` (a burnpack record) to `path` packed
/// ([`deepbrdf_data::packed`]: lossless, a few percent under the float bytes' size), atomically.
pub fn write_weights(path: &Path, weights: &[u8]) -> Result<()> {
    let packed = packed::pack(weights, Arrangement::Planes)?;
    write_atomic(path, &[&packed])
}

/// Reads a weights file written by [`write_weights`], or a plain burnpack record (as earlier
/// versions wrote it), back to the record's bytes; neither form may exceed `limit` bytes.
pub fn read_weights(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let bytes = read_limited(path, limit)?;
    match packed::is_packed(&bytes) {
        true => Ok(packed::unpack(path, &bytes, limit)?),
        false => Ok(bytes),
    }
}

/// Writes `manifest` to `path` as pretty-printed JSON with a final newline, atomically.
pub fn write_manifest(path: &Path, manifest: &impl Serialize) -> Result<()> {
    let json = serde_json::to_string_pretty(manifest)
        .map_err(|e| ModelError::Invalid(format!("cannot serialise the manifest: {e}")))?;
    write_atomic(path, &[json.as_bytes(), b"\n"])
}

/// Checks the `format` and `version` a manifest read from `path` declares against the format
/// this build reads (`expected`) and the versions it understands.
pub fn check_format(
    path: &Path,
    (format, version): (&str, u32),
    expected: &str,
    versions: RangeInclusive<u32>,
) -> Result<()> {
    if format == expected && versions.contains(&version) {
        return Ok(());
    }
    let wanted = match versions.start() == versions.end() {
        true => format!("version {}", versions.start()),
        false => format!("version {} to {}", versions.start(), versions.end()),
    };
    Err(ModelError::format(
        path,
        format!("format {format} version {version}, expected {expected} {wanted}"),
    ))
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

    #[test]
    fn weights_are_written_packed_and_read_in_either_form() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("weights.bpk");
        let record: Vec<u8> = (0..5000u32).flat_map(|i| (i as f32 * 0.01).to_le_bytes()).collect();
        write_weights(&path, &record).unwrap();
        let stored = fs::read(&path).unwrap();
        assert!(packed::is_packed(&stored) && stored.len() < record.len());
        assert_eq!(read_weights(&path, 1 << 20).unwrap(), record);
        // A plain record, as earlier versions wrote it, is read as it is.
        write_atomic(&path, &[&record]).unwrap();
        assert_eq!(read_weights(&path, 1 << 20).unwrap(), record);
        // Either form past the limit is refused, naming the file.
        let e = read_weights(&path, 100).unwrap_err().to_string();
        assert!(e.contains("weights.bpk"), "{e}");
        write_weights(&path, &record).unwrap();
        let e = read_weights(&path, stored.len() as u64).unwrap_err().to_string();
        assert!(e.contains("weights.bpk") && e.contains("more than"), "{e}");
    }

    #[test]
    fn formats_and_versions_outside_what_is_read_are_refused_by_name() {
        let path = Path::new("dir/model.json");
        assert!(check_format(path, ("f", 2), "f", 1..=2).is_ok());
        let e = check_format(path, ("f", 3), "f", 1..=2).unwrap_err().to_string();
        assert!(
            e.contains("dir/model.json")
                && e.ends_with("format f version 3, expected f version 1 to 2"),
            "{e}"
        );
        let e = check_format(path, ("g", 1), "f", 1..=1).unwrap_err().to_string();
        assert!(e.ends_with("format g version 1, expected f version 1"), "{e}");
    }

    #[test]
    fn a_manifest_is_pretty_json_with_a_final_newline() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        write_manifest(&path, &serde_json::json!({"a": 1})).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "{\n  \"a\": 1\n}\n");
    }
}

//! A small checksummed file of named binary sections: the regressor's file and training checkpoints.
//!
//! Layout: the 8-byte magic `DEEPBRDF`, an 8-byte kind tag, a little-endian `u32` section
//! count, then per section a `u32` name length, the UTF-8 name, a `u64` data length and the
//! data; last, the SHA-256 of everything before it. Reading checks every length against the
//! file size before allocating and verifies the checksum, so a truncated, damaged or foreign
//! file is an error naming the file, never a panic or a huge allocation.

use std::path::Path;

use sha2::{Digest, Sha256};

use super::files::{read_limited, write_atomic};
use crate::error::{ModelError, Result};

const MAGIC: &[u8; 8] = b"DEEPBRDF";
/// Largest container accepted (checkpoints of the Table 1 network are ~60 MB).
const MAX_BYTES: u64 = 8 << 30;

/// Named sections, in order.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Container {
    sections: Vec<(String, Vec<u8>)>,
}

impl Container {
    /// An empty container.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a section.
    pub fn push(&mut self, name: &str, data: Vec<u8>) {
        self.sections.push((name.to_string(), data));
    }

    /// The section named `name`, if any.
    pub fn get(&self, name: &str) -> Option<&[u8]> {
        self.sections.iter().find(|(n, _)| n == name).map(|(_, d)| d.as_slice())
    }

    /// Removes and returns the section named `name`, if any.
    pub fn take(&mut self, name: &str) -> Option<Vec<u8>> {
        let i = self.sections.iter().position(|(n, _)| n == name)?;
        Some(self.sections.remove(i).1)
    }

    /// Writes the container to `path` atomically (temporary file + rename).
    pub fn save(&self, path: &Path, kind: &[u8; 8]) -> Result<()> {
        let sections: Vec<(&str, &[u8])> =
            self.sections.iter().map(|(n, d)| (n.as_str(), d.as_slice())).collect();
        Self::save_sections(path, kind, &sections)
    }

    /// Writes a container of `sections` to `path` as [`save`](Self::save) does, from borrowed
    /// data (a checkpoint's 1.7 GB of weights are written where they are, not copied first).
    pub fn save_sections(path: &Path, kind: &[u8; 8], sections: &[(&str, &[u8])]) -> Result<()> {
        let mut head = Vec::new();
        head.extend_from_slice(MAGIC);
        head.extend_from_slice(kind);
        head.extend_from_slice(&(sections.len() as u32).to_le_bytes());
        let mut hasher = Sha256::new();
        let mut parts: Vec<Vec<u8>> = Vec::new();
        let mut pending = head;
        for (name, data) in sections {
            pending.extend_from_slice(&(name.len() as u32).to_le_bytes());
            pending.extend_from_slice(name.as_bytes());
            pending.extend_from_slice(&(data.len() as u64).to_le_bytes());
            hasher.update(&pending);
            hasher.update(data);
            parts.push(std::mem::take(&mut pending));
        }
        hasher.update(&pending);
        parts.push(pending);
        let digest = hasher.finalize();
        let mut slices: Vec<&[u8]> = Vec::new();
        for (i, (_, data)) in sections.iter().enumerate() {
            slices.push(&parts[i]);
            slices.push(data);
        }
        slices.push(&parts[sections.len()]);
        slices.push(&digest);
        write_atomic(path, &slices)
    }

    /// Reads a container of the given kind from `path`, verifying its checksum.
    pub fn load(path: &Path, kind: &[u8; 8]) -> Result<Self> {
        let bytes = read_limited(path, MAX_BYTES)?;
        let bad = |problem: String| ModelError::format(path, problem);
        if bytes.len() < 20 + 32 || &bytes[..8] != MAGIC {
            return Err(bad("not a DeepBRDF file (missing the DEEPBRDF header)".into()));
        }
        if &bytes[8..16] != kind {
            return Err(bad(format!(
                "a DeepBRDF {} file, expected {}",
                String::from_utf8_lossy(&bytes[8..16]).trim(),
                String::from_utf8_lossy(kind).trim()
            )));
        }
        let body_len = bytes.len() - 32;
        let digest = Sha256::digest(&bytes[..body_len]);
        if digest.as_slice() != &bytes[body_len..] {
            return Err(bad("checksum mismatch: the file is truncated or damaged".into()));
        }
        let body = &bytes[..body_len];
        let mut at = 16usize;
        let mut take = |n: usize| -> Result<&[u8]> {
            let end = at.checked_add(n).filter(|&e| e <= body.len());
            let end = end.ok_or_else(|| bad("a section runs past the end of the file".into()))?;
            let slice = &body[at..end];
            at = end;
            Ok(slice)
        };
        let count = u32::from_le_bytes(take(4)?.try_into().unwrap_or([0; 4])) as usize;
        let mut sections = Vec::new();
        for _ in 0..count {
            let name_len = u32::from_le_bytes(take(4)?.try_into().unwrap_or([0; 4])) as usize;
            let name = String::from_utf8(take(name_len)?.to_vec())
                .map_err(|_| bad("a section name is not UTF-8".into()))?;
            let len = u64::from_le_bytes(take(8)?.try_into().unwrap_or([0; 8]));
            let len = usize::try_from(len).map_err(|_| bad("a section is too large".into()))?;
            sections.push((name, take(len)?.to_vec()));
        }
        if at != body.len() {
            return Err(bad("trailing bytes after the last section".into()));
        }
        Ok(Self { sections })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_detects_damage() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.bin");
        let mut c = Container::new();
        c.push("state", b"{\"a\":1}".to_vec());
        c.push("empty", Vec::new());
        c.push("weights", vec![7u8; 1000]);
        c.save(&path, b"TESTKIND").unwrap();
        let back = Container::load(&path, b"TESTKIND").unwrap();
        assert_eq!(back, c);
        assert_eq!(back.get("weights").map(|w| w.len()), Some(1000));

        let err = Container::load(&path, b"OTHERKND").unwrap_err().to_string();
        assert!(err.contains("c.bin") && err.contains("expected"), "{err}");

        let mut bytes = std::fs::read(&path).unwrap();
        bytes[40] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        let err = Container::load(&path, b"TESTKIND").unwrap_err().to_string();
        assert!(err.contains("checksum"), "{err}");

        std::fs::write(&path, &bytes[..30]).unwrap();
        assert!(Container::load(&path, b"TESTKIND").is_err());
        std::fs::write(&path, b"hello").unwrap();
        assert!(Container::load(&path, b"TESTKIND").unwrap_err().to_string().contains("header"));
        assert!(Container::load(&dir.path().join("missing"), b"TESTKIND").is_err());
    }
}

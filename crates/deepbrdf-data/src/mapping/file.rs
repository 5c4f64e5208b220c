//! The file format of a saved [`MedianReference`], so a trained model is always used with the
//! reference it was trained with (a small checksummed binary format):
//!
//! | bytes            | content                                               |
//! |------------------|-------------------------------------------------------|
//! | 8                | magic `DBRDFMED`                                      |
//! | 4                | format version, u32 little-endian (= 1)               |
//! | 8                | number of values, u64 little-endian (= [`VALUES`])    |
//! | 4 x values       | the values, f32 little-endian, channel-major MERL order |
//! | 32               | SHA-256 of all preceding bytes                        |
//!
//! [`MedianReference::save_compressed`] writes the same bytes packed ([`crate::packed`], word
//! differences then byte planes then zstd: lossless, the values and their checksum are
//! unchanged); [`MedianReference::load`] reads that form, the plain one, and the single zstd
//! frame of the same bytes that earlier versions wrote, telling them apart by their first bytes.

use super::MedianReference;
use crate::error::{DataError, Result};
use crate::files::{open_regular, read_exactly, write_atomic};
use crate::merl::VALUES;
use crate::packed::{self, Arrangement};
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

/// Magic bytes that open a saved [`MedianReference`].
const MAGIC: &[u8; 8] = b"DBRDFMED";
/// Version of the saved format.
const VERSION: u32 = 1;
/// Bytes before the values: magic, version, length.
const HEADER_BYTES: usize = 8 + 4 + 8;
/// Bytes of the SHA-256 checksum at the end.
const CHECKSUM_BYTES: usize = 32;
/// Size of a valid saved reference.
const FILE_BYTES: usize = HEADER_BYTES + 4 * VALUES + CHECKSUM_BYTES;
/// The first bytes of a zstd frame.
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xB5, 0x2F, 0xFD];
/// The largest compressed file read: zstd adds a little to incompressible data, never this much.
const MAX_COMPRESSED_BYTES: u64 = FILE_BYTES as u64 + (1 << 20);

impl MedianReference {
    /// Saves the reference to `path` (format in the module documentation), atomically.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &self.to_bytes())
    }

    /// Saves the reference to `path` packed ([`crate::packed`]: the bytes [`Self::save`]
    /// writes, compressed losslessly), atomically; [`Self::load`] reads it back to the same
    /// values.
    pub fn save_compressed(&self, path: impl AsRef<Path>) -> Result<()> {
        let packed = packed::pack(&self.to_bytes(), Arrangement::DifferencePlanes)?;
        write_atomic(path.as_ref(), &packed)
    }

    /// The file format's bytes (module documentation).
    fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(FILE_BYTES);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&VERSION.to_le_bytes());
        bytes.extend_from_slice(&(self.values.len() as u64).to_le_bytes());
        for v in &self.values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let digest = Sha256::digest(&bytes);
        bytes.extend_from_slice(&digest);
        bytes
    }

    /// Loads a reference saved by [`Self::save`] or [`Self::save_compressed`] (or as one zstd
    /// frame, as earlier versions saved it). Every malformed
    /// file (empty, truncated, other magic, version or length, trailing bytes, checksum
    /// mismatch, invalid values, a damaged or oversized compressed form) is an error naming the
    /// file; nothing is allocated before the file's size has been checked, and a compressed
    /// file is never inflated past the size of the format.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (mut file, len) = open_regular(path)?;
        if len == 0 {
            return Err(DataError::format(path, "empty file, expected a median reference"));
        }
        let mut header = [0u8; HEADER_BYTES];
        let got = read_prefix(&mut file, path, &mut header)?;
        let packed = packed::is_packed(&header[..got]);
        if packed || (got >= ZSTD_MAGIC.len() && header[..4] == ZSTD_MAGIC) {
            if len > MAX_COMPRESSED_BYTES {
                return Err(DataError::format(
                    path,
                    format!("{len} bytes: too large for a compressed median reference"),
                ));
            }
            let mut bytes = header[..got].to_vec();
            file.read_to_end(&mut bytes).map_err(|e| DataError::io(path, e))?;
            return Self::from_compressed(path, &bytes);
        }
        check_header(path, &header[..got], len as usize)?;
        if len > FILE_BYTES as u64 {
            return Err(DataError::format(
                path,
                format!(
                    "{} trailing bytes after the expected {FILE_BYTES}",
                    len - FILE_BYTES as u64
                ),
            ));
        }
        let mut bytes = header[..got].to_vec();
        bytes.extend(read_exactly(&mut file, path, len as usize - got)?);
        Self::from_file_bytes(path, &bytes)
    }

    /// The reference in `packed`, the plain form packed ([`Self::save_compressed`]) or as one
    /// zstd frame (read from `path`, which errors name). Inflating stops with an error past the
    /// format's size, so no frame is expanded beyond it.
    fn from_compressed(path: &Path, packed: &[u8]) -> Result<Self> {
        if packed::is_packed(packed) {
            return Self::from_file_bytes(path, &packed::unpack(path, packed, FILE_BYTES as u64)?);
        }
        let raw = zstd::bulk::decompress(packed, FILE_BYTES).map_err(|e| {
            DataError::format(path, format!("a damaged compressed median reference: {e}"))
        })?;
        Self::from_file_bytes(path, &raw)
    }

    /// The reference in `bytes`, the whole of a file in the format of [`Self::save`] (read
    /// from `path`, which errors name).
    fn from_file_bytes(path: &Path, bytes: &[u8]) -> Result<Self> {
        let len = bytes.len();
        check_header(path, &bytes[..len.min(HEADER_BYTES)], len)?;
        if len < FILE_BYTES {
            return Err(DataError::format(
                path,
                format!("truncated: {len} bytes, expected {FILE_BYTES}"),
            ));
        }
        if len > FILE_BYTES {
            return Err(DataError::format(
                path,
                format!("{} trailing bytes after the expected {FILE_BYTES}", len - FILE_BYTES),
            ));
        }
        let (content, checksum) = bytes.split_at(len - CHECKSUM_BYTES);
        if Sha256::digest(content).as_slice() != checksum {
            return Err(DataError::format(path, "checksum mismatch: the file is corrupted"));
        }
        let values: Vec<f32> = content[HEADER_BYTES..]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Self::from_values(values).map_err(|e| DataError::format(path, e.to_string()))
    }
}

/// Checks the start of a reference file (`header`: its first bytes, up to [`HEADER_BYTES`];
/// `len`: the whole file's length): magic, version and number of values.
fn check_header(path: &Path, header: &[u8], len: usize) -> Result<()> {
    if header.len() < MAGIC.len() || &header[..8] != MAGIC {
        return Err(DataError::format(
            path,
            "not a median reference file (it does not start with DBRDFMED)",
        ));
    }
    if header.len() < HEADER_BYTES {
        return Err(DataError::format(path, format!("truncated: {len} bytes")));
    }
    let version = u32::from_le_bytes([header[8], header[9], header[10], header[11]]);
    if version != VERSION {
        return Err(DataError::format(
            path,
            format!("median reference format version {version}, this build reads {VERSION}"),
        ));
    }
    let mut n = [0u8; 8];
    n.copy_from_slice(&header[12..20]);
    let n = u64::from_le_bytes(n);
    if n != VALUES as u64 {
        return Err(DataError::format(
            path,
            format!("holds {n} values, a median reference has {VALUES}"),
        ));
    }
    Ok(())
}

/// Reads up to `buf.len()` bytes from the start of `file`; returns how many were read.
fn read_prefix(file: &mut std::fs::File, path: &Path, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match file.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(DataError::io(path, e)),
        }
    }
    Ok(got)
}

#[cfg(test)]
mod tests {
    use super::*;

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    #[test]
    fn save_load_round_trip_and_corruption_errors() -> TestResult {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("median.bin");
        let reference =
            MedianReference::from_values((0..VALUES).map(|i| (i % 977) as f32 * 0.013).collect())?;
        reference.save(&path)?;
        assert_eq!(MedianReference::load(&path)?, reference);
        let good = std::fs::read(&path)?;
        assert_eq!(good.len(), FILE_BYTES);

        let check = |bytes: &[u8], what: &str| -> TestResult {
            let p = dir.path().join("bad.bin");
            std::fs::write(&p, bytes)?;
            let msg = MedianReference::load(&p).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(msg.contains("bad.bin") && msg.contains(what), "{what}: {msg}");
            Ok(())
        };
        check(&[], "empty")?;
        check(b"hello world, not a reference", "DBRDFMED")?;
        check(&good[..15], "truncated")?;
        check(&good[..good.len() - 1], "truncated")?;
        let mut long = good.clone();
        long.push(0);
        check(&long, "trailing")?;
        let mut flipped = good.clone();
        flipped[HEADER_BYTES + 1000] ^= 1;
        check(&flipped, "checksum")?;
        let mut version = good.clone();
        version[8] = 9;
        check(&version, "version 9")?;
        let mut huge = good.clone();
        huge[12..20].copy_from_slice(&(1u64 << 40).to_le_bytes());
        check(&huge, "1099511627776 values")?;
        // A checksummed file with a NaN inside is still rejected.
        let mut nan = good[..good.len() - CHECKSUM_BYTES].to_vec();
        nan[HEADER_BYTES..HEADER_BYTES + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let digest = Sha256::digest(&nan);
        nan.extend_from_slice(&digest);
        check(&nan, "value 0")?;
        // The packed form: the same values back; damaged packed files are errors naming the file.
        let packed = dir.path().join("median.bin.packed");
        reference.save_compressed(&packed)?;
        assert!(std::fs::metadata(&packed)?.len() < FILE_BYTES as u64 / 2);
        assert_eq!(MedianReference::load(&packed)?, reference);
        let stored = std::fs::read(&packed)?;
        check(&stored[..stored.len() / 2], "damaged packed")?;
        // The single zstd frame that earlier versions saved still loads to the same values;
        // damaged, oversized or foreign frames are errors naming the file.
        let frame = zstd::bulk::compress(&good, 3)?;
        let old = dir.path().join("median.bin.zst");
        std::fs::write(&old, &frame)?;
        assert_eq!(MedianReference::load(&old)?, reference);
        check(&frame[..frame.len() / 2], "damaged compressed")?;
        let bomb = zstd::bulk::compress(&vec![0u8; 4 * FILE_BYTES], 3)?;
        check(&bomb, "damaged compressed")?;
        check(&zstd::bulk::compress(b"hello world", 3)?, "DBRDFMED")?;
        let mut flipped_inside = good.clone();
        flipped_inside[HEADER_BYTES + 7] ^= 1;
        check(&zstd::bulk::compress(&flipped_inside, 3)?, "checksum")?;
        let msg = MedianReference::load(dir.path()).err().map(|e| e.to_string());
        assert!(msg.unwrap_or_default().contains("directory"));
        Ok(())
    }

    #[test]
    fn mutated_compressed_references_are_rejected_or_read_never_a_panic() -> TestResult {
        use crate::testing::mutate::{fuzz, inputs, Focus};
        let reference =
            MedianReference::from_values((0..VALUES).map(|i| (i % 541) as f32 * 0.021).collect())?;
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("median.bin");
        reference.save_compressed(&path)?;
        // Both compressed forms: packed, and the single zstd frame of earlier versions.
        let corpus = vec![std::fs::read(&path)?, zstd::bulk::compress(&reference.to_bytes(), 3)?];
        let origin = Path::new("fuzz.bin");
        // Each accepted input inflates to 17.5 MB and is hashed: fewer inputs than the others.
        let report = fuzz(&corpus, 13, inputs(300), Focus::default(), |b| {
            MedianReference::from_compressed(origin, b)
        });
        eprintln!("compressed median reference reader: {report:?}");
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert!(report.rejected > 0, "{report:?}");
        let msg =
            MedianReference::load(dir.path().join("missing.bin")).err().map(|e| e.to_string());
        assert!(msg.unwrap_or_default().contains("missing.bin"));
        Ok(())
    }
}

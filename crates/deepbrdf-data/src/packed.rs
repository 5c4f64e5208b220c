//! Lossless compact storage of files made of little-endian 32-bit floats (a network's weights,
//! the eq. (1) median reference of a model): the bytes rearranged so that zstd finds their
//! redundancy, then one zstd frame. Unpacking gives back the very bytes that were packed, so
//! checksums taken over the unpacked bytes (a model's id) do not change.
//!
//! | bytes | content                                                        |
//! |-------|----------------------------------------------------------------|
//! | 8     | magic `DBRDFPK1`                                               |
//! | 1     | the arrangement: 0 byte planes, 1 word differences then planes |
//! | 8     | length of the unpacked bytes, u64 little-endian                |
//! | rest  | one zstd frame of the arranged bytes                           |
//!
//! Byte planes: every fourth byte from the first, then from the second, third and fourth (the
//! bytes past the last whole word stay last), so the sign-and-exponent bytes of the floats sit
//! together and compress, where interleaved with the mantissas they do not. Word differences:
//! each 32-bit word minus the one before it (wrapping), for tables whose neighbouring values
//! are close, such as the median of MERL tables along phi_d.

use crate::error::{DataError, Result};
use std::io::Read;
use std::path::Path;

/// Magic bytes that open a packed file.
pub const MAGIC: &[u8; 8] = b"DBRDFPK1";
/// Bytes before the zstd frame.
const HEADER_BYTES: usize = 8 + 1 + 8;
/// zstd's level: the higher levels shrink a median reference by a few percent more and take
/// tens of times longer.
const ZSTD_LEVEL: i32 = 9;

/// How the bytes are arranged before compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arrangement {
    /// Byte planes of the 32-bit words (weights: neighbouring values are unrelated).
    Planes,
    /// Differences of consecutive 32-bit words, then byte planes (smooth tables).
    DifferencePlanes,
}

impl Arrangement {
    fn code(self) -> u8 {
        match self {
            Arrangement::Planes => 0,
            Arrangement::DifferencePlanes => 1,
        }
    }

    fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Arrangement::Planes),
            1 => Some(Arrangement::DifferencePlanes),
            _ => None,
        }
    }
}

/// Whether `bytes` start as a packed file does.
pub fn is_packed(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// `bytes` packed (format in the module documentation).
pub fn pack(bytes: &[u8], arrangement: Arrangement) -> Result<Vec<u8>> {
    let mut words = bytes.to_vec();
    if arrangement == Arrangement::DifferencePlanes {
        differences(&mut words);
    }
    let frame = zstd::bulk::compress(&planes(&words), ZSTD_LEVEL)
        .map_err(|e| DataError::Invalid(format!("cannot compress: {e}")))?;
    let mut out = Vec::with_capacity(HEADER_BYTES + frame.len());
    out.extend_from_slice(MAGIC);
    out.push(arrangement.code());
    out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
    out.extend_from_slice(&frame);
    Ok(out)
}

/// The bytes packed in `packed` (read from `path`, which errors name). A file that declares
/// more than `max_len` bytes is refused before anything is allocated, and inflating stops one
/// byte past the declared length, so a damaged or hostile frame never expands beyond it.
pub fn unpack(path: &Path, packed: &[u8], max_len: u64) -> Result<Vec<u8>> {
    let bad = |problem: String| DataError::format(path, problem);
    if !is_packed(packed) || packed.len() < HEADER_BYTES {
        return Err(bad(
            "not a packed file (it does not start with DBRDFPK1 and its header)".into()
        ));
    }
    let arrangement = Arrangement::from_code(packed[8])
        .ok_or_else(|| bad(format!("unknown byte arrangement {} in a packed file", packed[8])))?;
    let mut len = [0u8; 8];
    len.copy_from_slice(&packed[9..HEADER_BYTES]);
    let len = u64::from_le_bytes(len);
    if len > max_len {
        return Err(bad(format!("a packed file of {len} bytes, more than the {max_len} allowed")));
    }
    let decoder = zstd::stream::read::Decoder::new(&packed[HEADER_BYTES..])
        .map_err(|e| bad(format!("a damaged packed file: {e}")))?;
    let mut arranged = Vec::new();
    decoder
        .take(len + 1)
        .read_to_end(&mut arranged)
        .map_err(|e| bad(format!("a damaged packed file: {e}")))?;
    if arranged.len() as u64 != len {
        return Err(bad(format!(
            "a damaged packed file: {} bytes inside, its header says {len}",
            arranged.len()
        )));
    }
    let mut words = interleave(&arranged);
    if arrangement == Arrangement::DifferencePlanes {
        sums(&mut words);
    }
    Ok(words)
}

/// The byte planes of `bytes` (module documentation).
fn planes(bytes: &[u8]) -> Vec<u8> {
    let whole = bytes.len() / 4 * 4;
    let mut out = Vec::with_capacity(bytes.len());
    for plane in 0..4 {
        out.extend(bytes[..whole].iter().skip(plane).step_by(4));
    }
    out.extend_from_slice(&bytes[whole..]);
    out
}

/// The inverse of [`planes`].
fn interleave(arranged: &[u8]) -> Vec<u8> {
    let words = arranged.len() / 4;
    let mut out = vec![0u8; arranged.len()];
    for plane in 0..4 {
        for (i, &b) in arranged[plane * words..(plane + 1) * words].iter().enumerate() {
            out[4 * i + plane] = b;
        }
    }
    out[4 * words..].copy_from_slice(&arranged[4 * words..]);
    out
}

/// Replaces each whole 32-bit word of `bytes` after the first by its difference from the
/// previous word (wrapping).
fn differences(bytes: &mut [u8]) {
    let mut previous = 0u32;
    for word in bytes.chunks_exact_mut(4) {
        let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
        word.copy_from_slice(&value.wrapping_sub(previous).to_le_bytes());
        previous = value;
    }
}

/// The inverse of [`differences`].
fn sums(bytes: &mut [u8]) {
    let mut previous = 0u32;
    for word in bytes.chunks_exact_mut(4) {
        let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]).wrapping_add(previous);
        word.copy_from_slice(&value.to_le_bytes());
        previous = value;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    #[test]
    fn packing_gives_back_the_same_bytes_and_shrinks_smooth_floats() -> TestResult {
        let smooth: Vec<u8> =
            (0..100_000).flat_map(|i| (1.0 + (i as f32 * 1e-3).sin()).to_le_bytes()).collect();
        for arrangement in [Arrangement::Planes, Arrangement::DifferencePlanes] {
            for bytes in [&smooth[..], &smooth[..4001], &smooth[..3], &[][..]] {
                let packed = pack(bytes, arrangement)?;
                assert!(is_packed(&packed));
                assert_eq!(unpack(Path::new("p"), &packed, bytes.len() as u64)?, bytes);
            }
        }
        let plain = zstd::bulk::compress(&smooth, ZSTD_LEVEL)?.len();
        let arranged = pack(&smooth, Arrangement::DifferencePlanes)?.len();
        assert!(arranged < plain * 3 / 4, "{arranged} vs {plain}");
        Ok(())
    }

    #[test]
    fn damaged_oversized_and_foreign_files_are_refused_by_name() -> TestResult {
        let bytes: Vec<u8> = (0..4000u32).flat_map(|i| (i as f32).to_le_bytes()).collect();
        let good = pack(&bytes, Arrangement::Planes)?;
        let check = |packed: &[u8], max: u64, what: &str| {
            let msg = unpack(Path::new("w.bpk"), packed, max).err().map(|e| e.to_string());
            let msg = msg.unwrap_or_default();
            assert!(msg.contains("w.bpk") && msg.contains(what), "{what}: {msg}");
        };
        check(b"burnpack", 1 << 20, "not a packed file");
        check(&good[..12], 1 << 20, "not a packed file");
        check(&good, bytes.len() as u64 - 1, "more than");
        check(&good[..good.len() - 9], 1 << 20, "damaged");
        let mut arrangement = good.clone();
        arrangement[8] = 7;
        check(&arrangement, 1 << 20, "arrangement 7");
        let mut longer = good.clone();
        longer[9..17].copy_from_slice(&(bytes.len() as u64 + 4).to_le_bytes());
        check(&longer, 1 << 20, "its header says");
        let mut shorter = good.clone();
        shorter[9..17].copy_from_slice(&(bytes.len() as u64 - 4).to_le_bytes());
        check(&shorter, 1 << 20, "its header says");
        let mut bomb = MAGIC.to_vec();
        bomb.push(0);
        bomb.extend_from_slice(&16u64.to_le_bytes());
        bomb.extend(zstd::bulk::compress(&vec![0u8; 1 << 24], 3)?);
        check(&bomb, 1 << 20, "its header says");
        Ok(())
    }

    #[test]
    fn mutated_packed_files_are_refused_or_read_never_a_panic() -> TestResult {
        use crate::testing::mutate::{fuzz, inputs, Focus};
        let bytes: Vec<u8> = (0..20_000u32).flat_map(|i| (i as f32 * 0.37).to_le_bytes()).collect();
        let corpus = vec![pack(&bytes, Arrangement::DifferencePlanes)?];
        let focus = Focus { header: HEADER_BYTES + 16, header_share: 0.5 };
        let report =
            fuzz(&corpus, 17, inputs(2_000), focus, |b| unpack(Path::new("fuzz"), b, 1 << 20));
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert!(report.rejected > 0, "{report:?}");
        Ok(())
    }
}

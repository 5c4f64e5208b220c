//! A deterministic mutation fuzzer for the readers of outside bytes (MERL `.binary`, `.nbrdf`
//! packs, cached tables, model artifacts, latent files, configs, RGL tensor files): it derives
//! inputs from real files by truncation, bit flips, byte and field overwrites (size fields set to
//! 0, 1, 2^31 - 1, -1, ...), NaN and infinities written over float fields, and spliced or
//! repeated stretches, and checks that the reader returns (Ok or Err) without panicking.
//!
//! Coverage-guided fuzzers (cargo-fuzz, AFL) need a nightly toolchain or their own compiler
//! wrappers, which this project's stable toolchain does not have; property tests over mutations
//! of real files are what the reliability issue asks for instead. Every run is seeded and the
//! inputs of a run are a pure function of the seed and the seed corpus, so a crash found by a
//! long run (`DEEPBRDF_FUZZ_INPUTS=1000000`) is reproduced by its index.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Environment variable that sets the number of inputs per reader (default: [`DEFAULT_INPUTS`]).
pub const INPUTS_VAR: &str = "DEEPBRDF_FUZZ_INPUTS";
/// Inputs per reader in the normal test suite (a few seconds).
pub const DEFAULT_INPUTS: usize = 3_000;

/// Inputs per reader for this run: [`INPUTS_VAR`] if set to a number, else `default`.
pub fn inputs(default: usize) -> usize {
    std::env::var(INPUTS_VAR).ok().and_then(|v| v.trim().parse().ok()).unwrap_or(default)
}

/// Where mutations go: a format with a small header and a large body (MERL) gets most of its
/// mutations in the header, where the parser makes its decisions.
#[derive(Debug, Clone, Copy)]
pub struct Focus {
    /// Bytes at the start that hold the header (sizes, magic, counts).
    pub header: usize,
    /// Probability that a mutation lands in the header rather than anywhere.
    pub header_share: f64,
}

impl Default for Focus {
    fn default() -> Self {
        Self { header: 64, header_share: 0.5 }
    }
}

/// What a fuzz run saw.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    /// Inputs given to the reader.
    pub inputs: usize,
    /// Inputs the reader accepted.
    pub accepted: usize,
    /// Inputs the reader rejected with an error.
    pub rejected: usize,
    /// Indices of inputs on which the reader panicked, with the panic message.
    pub panics: Vec<(usize, String)>,
}

/// Values written over 4- and 8-byte fields: the extremes size checks must survive.
const U32_EXTREMES: [u32; 8] = [0, 1, 2, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 1 << 30, 1 << 20];
const F32_SPECIALS: [f32; 5] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, f32::MAX];
const F64_SPECIALS: [f64; 5] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e300, f64::MAX];

/// The `index`-th mutation of one of `corpus`'s files (deterministic in `seed` and `index`).
pub fn mutant(corpus: &[Vec<u8>], seed: u64, index: usize, focus: Focus) -> Vec<u8> {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let mut bytes = corpus[rng.random_range(0..corpus.len())].clone();
    let rounds = 1 + (rng.random::<u32>() % 3) as usize;
    for _ in 0..rounds {
        mutate(&mut bytes, &mut rng, focus);
    }
    bytes
}

/// Applies one random mutation to `bytes`.
fn mutate(bytes: &mut Vec<u8>, rng: &mut ChaCha8Rng, focus: Focus) {
    let len = bytes.len();
    let at = |rng: &mut ChaCha8Rng, width: usize| -> Option<usize> {
        if len < width {
            return None;
        }
        let span = if rng.random_bool(focus.header_share) { focus.header.min(len) } else { len };
        Some(rng.random_range(0..=span.saturating_sub(width)))
    };
    match rng.random_range(0..9u32) {
        0 => {
            let keep = if len == 0 { 0 } else { rng.random_range(0..len) };
            bytes.truncate(keep);
        }
        1 => {
            if let Some(i) = at(rng, 1) {
                bytes[i] ^= 1 << rng.random_range(0..8);
            }
        }
        2 => {
            if let Some(i) = at(rng, 1) {
                bytes[i] = rng.random();
            }
        }
        3 => {
            if let Some(i) = at(rng, 4) {
                let v = U32_EXTREMES[rng.random_range(0..U32_EXTREMES.len())];
                bytes[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        4 => {
            if let Some(i) = at(rng, 8) {
                let v =
                    if rng.random_bool(0.5) { u64::MAX } else { 1u64 << rng.random_range(20..64) };
                bytes[i..i + 8].copy_from_slice(&v.to_le_bytes());
            }
        }
        5 => {
            // Float specials at an aligned offset, where real float fields live.
            if let Some(i) = at(rng, 4) {
                let i = i & !3;
                let v = F32_SPECIALS[rng.random_range(0..F32_SPECIALS.len())];
                bytes[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        6 => {
            if let Some(i) = at(rng, 8) {
                let i = i & !7;
                if i + 8 <= len {
                    let v = F64_SPECIALS[rng.random_range(0..F64_SPECIALS.len())];
                    bytes[i..i + 8].copy_from_slice(&v.to_le_bytes());
                }
            }
        }
        7 => {
            // Repeat a stretch (lengthens the file: trailing bytes, shifted fields).
            if let Some(i) = at(rng, 1) {
                let n = rng.random_range(1..=64.min(len - i));
                let stretch: Vec<u8> = bytes[i..i + n].to_vec();
                let j = rng.random_range(i..=len);
                bytes.splice(j..j, stretch);
            }
        }
        _ => {
            // Delete a stretch (shifts every later field).
            if let Some(i) = at(rng, 1) {
                let n = rng.random_range(1..=64.min(len - i));
                bytes.drain(i..i + n);
            }
        }
    }
}

/// Feeds `n` mutants of `corpus` to `read` and reports what happened. Panics are caught (and
/// the default panic message silenced) so that one run lists every failing index.
pub fn fuzz<T, E>(
    corpus: &[Vec<u8>],
    seed: u64,
    n: usize,
    focus: Focus,
    mut read: impl FnMut(&[u8]) -> Result<T, E>,
) -> Report {
    assert!(!corpus.is_empty(), "a fuzz run needs at least one seed file");
    let mut report = Report { inputs: n, ..Report::default() };
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for index in 0..n {
        let input = mutant(corpus, seed, index, focus);
        match catch_unwind(AssertUnwindSafe(|| read(&input).is_ok())) {
            Ok(true) => report.accepted += 1,
            Ok(false) => report.rejected += 1,
            Err(payload) => {
                let message = payload
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "non-string panic".into());
                report.panics.push((index, message));
            }
        }
    }
    std::panic::set_hook(hook);
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutants_are_deterministic_and_varied() {
        let corpus = vec![(0u8..200).collect::<Vec<u8>>()];
        let a: Vec<Vec<u8>> = (0..50).map(|i| mutant(&corpus, 7, i, Focus::default())).collect();
        let b: Vec<Vec<u8>> = (0..50).map(|i| mutant(&corpus, 7, i, Focus::default())).collect();
        assert_eq!(a, b);
        let distinct: std::collections::HashSet<&Vec<u8>> = a.iter().collect();
        assert!(distinct.len() > 40, "only {} distinct mutants of 50", distinct.len());
        assert!(a.iter().any(|m| m.len() < 200) && a.iter().any(|m| m.len() > 200));
    }

    #[test]
    fn a_panicking_reader_is_reported_with_the_index() {
        let corpus = vec![vec![1u8; 16]];
        // A reader with the classic bug: trusts the first byte as a length.
        let report = fuzz(&corpus, 1, 500, Focus::default(), |b: &[u8]| -> Result<u8, ()> {
            let n = *b.first().ok_or(())? as usize;
            Ok(b[n])
        });
        assert_eq!(report.inputs, 500);
        assert!(!report.panics.is_empty(), "the out-of-bounds read must be found");
        assert_eq!(report.accepted + report.rejected + report.panics.len(), 500);
    }
}

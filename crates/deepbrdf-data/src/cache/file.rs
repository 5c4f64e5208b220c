//! One cached table file of the table cache ([`super::Cache`]): its bytes, written by [`encode`]
//! and checked by [`decode`] before anything in them is trusted.
//!
//! Layout (little-endian): magic `DBRDFTAB` (8 bytes), format version u32 ([`FORMAT_VERSION`]),
//! tabulator version u32, key (32 bytes), XXH3-128 of the values (16 bytes), then [`VALUES`]
//! f32: always [`FILE_BYTES`] bytes.
//!
//! The checksum is there to catch damage (flipped bits, a file cut short or spliced), not
//! forgery: the key says whose table a file holds; XXH3-128 adds under 1 ms to a 35 MB read
//! (format 1's SHA-256 cost a third of it: CHANGELOG.md). A file of format 1 is refused by its
//! size (with the warning of any damaged file) and tabulated again.

use crate::error::{DataError, Result};
use crate::merl::{MerlTable, VALUES};
use std::path::Path;
use xxhash_rust::xxh3::xxh3_128;

/// Magic bytes opening a cached table.
const MAGIC: [u8; 8] = *b"DBRDFTAB";
/// Version of the file layout (2: XXH3-128 instead of SHA-256, a 64-byte header).
pub const FORMAT_VERSION: u32 = 2;
/// Where the key starts.
const KEY_AT: usize = 16;
/// Where the checksum of the values starts.
const SUM_AT: usize = KEY_AT + 32;
/// Bytes before the values.
pub const HEADER: usize = SUM_AT + 16;
/// Exact size of a cached table file.
pub const FILE_BYTES: usize = HEADER + VALUES * 4;

/// The file of `table` under `key`, tabulated by tabulator `version`.
pub fn encode(key: &[u8; 32], version: u32, table: &MerlTable) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(FILE_BYTES);
    bytes.extend(MAGIC);
    bytes.extend(FORMAT_VERSION.to_le_bytes());
    bytes.extend(version.to_le_bytes());
    bytes.extend(key);
    bytes.extend([0u8; 16]);
    bytes.extend(table.values().iter().flat_map(|v| v.to_le_bytes()));
    seal(&mut bytes);
    bytes
}

/// Writes the checksum of the values after the header into the header (`bytes` at least
/// [`HEADER`] long).
fn seal(bytes: &mut [u8]) {
    let sum = checksum(&bytes[HEADER..]);
    bytes[SUM_AT..HEADER].copy_from_slice(&sum);
}

/// XXH3-128 of `payload`, little-endian.
fn checksum(payload: &[u8]) -> [u8; 16] {
    xxh3_128(payload).to_le_bytes()
}

/// Why a file of `len` bytes is not a cached table.
fn size_problem(len: u64) -> String {
    format!("{len} bytes, a cached table (format {FORMAT_VERSION}) has {FILE_BYTES}")
}

/// The table in `bytes`, the content of the file at `path` (named in every error), if they are a
/// cached table under `key` of tabulator `version`: size, magic, versions, key and checksum are
/// checked, in that order, before a value is decoded.
pub fn decode(bytes: &[u8], path: &Path, key: &[u8; 32], version: u32) -> Result<MerlTable> {
    if bytes.len() != FILE_BYTES {
        return Err(DataError::format(path, size_problem(bytes.len() as u64)));
    }
    let u32_at =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    if bytes[..8] != MAGIC || u32_at(8) != FORMAT_VERSION || u32_at(12) != version {
        return Err(DataError::format(path, "not a cached table of this version"));
    }
    if bytes[KEY_AT..SUM_AT] != key[..] {
        return Err(DataError::format(path, "cached table of another network"));
    }
    let payload = &bytes[HEADER..];
    if checksum(payload) != bytes[SUM_AT..HEADER] {
        return Err(DataError::format(path, "checksum mismatch"));
    }
    let values: Vec<f32> =
        payload.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    MerlTable::from_values(values).map_err(|e| DataError::format(path, e.to_string()))
}

/// Reads the cached table at `path`: `Ok(None)` if there is no file, `Err` (naming the file) if
/// it is not a valid table for `key`. A file of the wrong size is refused before it is read.
pub fn read(path: &Path, key: &[u8; 32], version: u32) -> Result<Option<MerlTable>> {
    use std::io::Read;
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(DataError::io(path, e)),
    };
    let len = file.metadata().map_err(|e| DataError::io(path, e))?.len();
    if len != FILE_BYTES as u64 {
        return Err(DataError::format(path, size_problem(len)));
    }
    // One byte more than a table, so a file that grew since its size was read is refused.
    let mut bytes = Vec::with_capacity(FILE_BYTES + 1);
    file.take(FILE_BYTES as u64 + 1).read_to_end(&mut bytes).map_err(|e| DataError::io(path, e))?;
    decode(&bytes, path, key, version).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::mutate::{fuzz, inputs, Focus, Report};
    use std::time::Instant;

    const KEY: [u8; 32] = *b"a key of thirty-two bytes, fixed";
    const VERSION: u32 = 3;
    /// The name every refusal must carry.
    const NAME: &str = "fuzz-0123456789abcdef.tab";

    /// A table with valid and invalid cells and varied values.
    fn table() -> MerlTable {
        MerlTable::from_fn(|h, d, p| {
            let v = 0.01 + (h as f32 * 0.07 + d as f32 * 0.013 + p as f32 * 0.003).sin().abs();
            [v, 0.5 * v, 0.25 * v + 1e-4]
        })
    }

    fn problem(bytes: &[u8]) -> String {
        decode(bytes, Path::new(NAME), &KEY, VERSION).expect_err("must be refused").to_string()
    }

    #[test]
    fn a_table_round_trips_and_each_check_refuses_naming_the_file() {
        let table = table();
        let bytes = encode(&KEY, VERSION, &table);
        assert_eq!(bytes.len(), FILE_BYTES);
        assert_eq!(decode(&bytes, Path::new(NAME), &KEY, VERSION).expect("valid"), table);
        let cases: [(&dyn Fn(&mut Vec<u8>), &str); 7] = [
            (&|b| b.truncate(FILE_BYTES - 1), "bytes, a cached table (format 2) has"),
            (&|b| b.push(0), "bytes, a cached table (format 2) has"),
            (&|b| b[0] = b'X', "not a cached table of this version"),
            (&|b| b[8..12].copy_from_slice(&1u32.to_le_bytes()), "not a cached table of this"),
            (&|b| b[12..16].copy_from_slice(&4u32.to_le_bytes()), "not a cached table of this"),
            (&|b| b[KEY_AT + 5] ^= 1, "cached table of another network"),
            (&|b| b[FILE_BYTES - 1] ^= 0x40, "checksum mismatch"),
        ];
        for (damage, expected) in cases {
            let mut b = bytes.clone();
            damage(&mut b);
            let message = problem(&b);
            assert!(message.contains(NAME) && message.contains(expected), "{message}");
        }
        // A value that is not finite, behind a checksum that matches it.
        let mut b = bytes.clone();
        b[HEADER + 400..HEADER + 404].copy_from_slice(&f32::NAN.to_le_bytes());
        seal(&mut b);
        let message = problem(&b);
        assert!(message.contains(NAME) && message.contains("not finite"), "{message}");
    }

    #[test]
    fn a_missing_file_is_none_and_a_file_of_format_1_is_refused_before_it_is_read() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(NAME);
        assert!(read(&path, &KEY, VERSION).expect("no file").is_none());
        // Format 1: the same magic and versions, a 32-byte SHA-256 (80-byte header).
        let mut old = vec![0u8; 80 + VALUES * 4];
        old[..8].copy_from_slice(&MAGIC);
        old[8..12].copy_from_slice(&1u32.to_le_bytes());
        std::fs::write(&path, &old).expect("write");
        let message = read(&path, &KEY, VERSION).expect_err("format 1").to_string();
        assert!(message.contains(NAME) && message.contains(&format!("{}", old.len())), "{message}");
        std::fs::write(&path, encode(&KEY, VERSION, &table())).expect("write");
        assert_eq!(read(&path, &KEY, VERSION).expect("valid"), Some(table()));
        let message = read(dir.path(), &KEY, VERSION).expect_err("a directory").to_string();
        assert!(message.contains(&dir.path().display().to_string()), "{message}");
    }

    /// Bytes at one end of the file that a mutant replaces.
    const WINDOW: usize = 4096;
    /// Room for mutants longer than the window (three rounds add at most 192 bytes).
    const SLACK: usize = 1024;

    /// A valid file with one end (`WINDOW` bytes) replaced by a mutant of it, assembled in place
    /// in one buffer: the other 35 MB are neither copied nor hashed to build an input.
    struct Splice {
        buf: Vec<u8>,
        /// The mutant replaces the first `WINDOW` bytes (the header and the start of the values)
        /// when true, the last `WINDOW` (the end of the values) when false.
        head: bool,
        /// A mutant too long for `SLACK`, assembled by copying.
        spill: Vec<u8>,
    }

    impl Splice {
        fn new(file: &[u8], head: bool) -> Self {
            let buf = match head {
                true => [&[0u8; SLACK][..], file].concat(),
                false => [file, &[0u8; SLACK][..]].concat(),
            };
            Self { buf, head, spill: Vec::new() }
        }

        /// The window of the valid file, the seed of the mutants.
        fn window(&self) -> Vec<u8> {
            match self.head {
                true => self.buf[SLACK..SLACK + WINDOW].to_vec(),
                false => self.buf[FILE_BYTES - WINDOW..FILE_BYTES].to_vec(),
            }
        }

        /// The file with its window replaced by `mutant`.
        fn with(&mut self, mutant: &[u8]) -> &mut [u8] {
            let n = mutant.len();
            if n > WINDOW + SLACK {
                self.spill = match self.head {
                    true => [mutant, &self.buf[SLACK + WINDOW..]].concat(),
                    false => [&self.buf[..FILE_BYTES - WINDOW], mutant].concat(),
                };
                return &mut self.spill;
            }
            if self.head {
                let start = SLACK + WINDOW - n;
                self.buf[start..SLACK + WINDOW].copy_from_slice(mutant);
                &mut self.buf[start..]
            } else {
                let start = FILE_BYTES - WINDOW;
                self.buf[start..start + n].copy_from_slice(mutant);
                &mut self.buf[..start + n]
            }
        }
    }

    /// What one fuzz run found beyond the [`Report`].
    #[derive(Debug, Default)]
    struct Findings {
        /// Refusals whose message does not name the file.
        unnamed: usize,
        /// Accepted inputs whose table differs from the original (damage that got through).
        damaged: usize,
    }

    /// `n` mutants of one end of `file` (resealed: with the checksum recomputed over the mutated
    /// values, so the checks after it see the damage) given to [`decode`].
    fn run(
        file: &[u8],
        original: &MerlTable,
        head: bool,
        resealed: bool,
        seed: u64,
        n: usize,
    ) -> (Report, Findings, f64) {
        let started = Instant::now();
        let mut splice = Splice::new(file, head);
        let corpus = vec![splice.window()];
        let focus = match head {
            true => Focus { header: HEADER, header_share: 0.9 },
            false => Focus { header: 0, header_share: 0.0 },
        };
        let mut findings = Findings::default();
        let report = fuzz(&corpus, seed, n, focus, |mutant| {
            let bytes = splice.with(mutant);
            if resealed && bytes.len() >= HEADER {
                seal(bytes);
            }
            let result = decode(bytes, Path::new(NAME), &KEY, VERSION);
            match &result {
                Ok(table) if !resealed && table != original => findings.damaged += 1,
                Err(e) if !e.to_string().contains(NAME) => findings.unnamed += 1,
                _ => {}
            }
            result
        });
        (report, findings, started.elapsed().as_secs_f64())
    }

    /// Mutants of the header end (most of them) and of the values' end of a valid file; a few
    /// resealed. `DEEPBRDF_FUZZ_INPUTS=N` sets the total.
    #[test]
    fn mutated_cache_files_are_refused_or_read_never_a_panic() {
        let original = table();
        let file = encode(&KEY, VERSION, &original);
        let n = inputs(3_000);
        let resealed = (n / 100).max(40);
        let payload = n / 10;
        let header = n - payload - 2 * resealed;
        let runs = [
            ("header end", true, false, header),
            ("values' end", false, false, payload),
            ("header end, resealed", true, true, resealed),
            ("values' end, resealed", false, true, resealed),
        ];
        let mut total = Report::default();
        let mut seconds = 0.0;
        for (seed, (what, head, reseal, count)) in runs.into_iter().enumerate() {
            let (report, findings, s) =
                run(&file, &original, head, reseal, 40 + seed as u64, count);
            eprintln!("cache file reader, {what}: {count} inputs, {} read, {} refused, {} panics, {findings:?}, {s:.1} s",
                report.accepted, report.rejected, report.panics.len());
            assert!(report.panics.is_empty(), "{what}: panics: {:?}", report.panics);
            assert_eq!(report.accepted + report.rejected, count, "{what}");
            assert_eq!((findings.unnamed, findings.damaged), (0, 0), "{what}: {findings:?}");
            assert!(report.rejected > 0, "{what}: nothing refused");
            if reseal {
                assert!(report.accepted > 0, "{what}: nothing got past the checksum");
            }
            total.inputs += report.inputs;
            total.accepted += report.accepted;
            total.rejected += report.rejected;
            seconds += s;
        }
        eprintln!(
            "cache file reader: {} inputs, {} read, {} refused naming the file, 0 panics; {seconds:.1} s",
            total.inputs, total.accepted, total.rejected
        );
        assert_eq!(total.inputs, n);
    }
}

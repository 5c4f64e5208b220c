//! Reading and writing MERL `.binary` files (Matusik et al. 2003, format of MERL's reference
//! reader `BRDFRead.cpp`): a header of three little-endian i32, the grid dimensions
//! (90, 90, 180 = theta_h, theta_d, phi_d samples), then the red, green and blue blocks of
//! [`CELLS`] little-endian f64 each, in MERL order. Stored values times the channel's colour scale
//! ([`MERL_SCALE`]) are reflectance in 1/sr; negative stored values mark invalid cells.
//!
//! [`MerlFile`] keeps the stored f64 values as they are, for byte-exact round trips;
//! [`read_merl`] / [`write_merl`] convert to and from the f32 [`MerlTable`] in physical units.
//! Sizes are checked before anything is allocated and writes are atomic.

use super::grid::{CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use super::table::{MerlTable, INVALID_VALUE, MERL_SCALE};
use crate::error::{DataError, Result};
use crate::files::{open_regular, read_exactly, write_atomic};
use std::io::Read;
use std::path::Path;

/// Bytes of the header: three i32.
pub const HEADER_BYTES: usize = 12;
/// Bytes of a MERL file: header plus 3 x 1,458,000 f64 = 34,992,012.
pub const FILE_BYTES: usize = HEADER_BYTES + 8 * 3 * CELLS;
/// The stored value written for invalid cells (MERL's files use negative values there).
pub const INVALID_STORED: f64 = -1.0;
/// The header dimensions a MERL file must have.
const DIMS: [i32; 3] = [N_THETA_H as i32, N_THETA_D as i32, N_PHI_D as i32];

/// A MERL file's content as stored: 3 x [`CELLS`] f64 (R, G, B blocks, MERL order), before the
/// colour scales. Reading and writing it reproduces a file byte for byte.
#[derive(Clone, PartialEq)]
pub struct MerlFile {
    stored: Vec<f64>,
}

impl std::fmt::Debug for MerlFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MerlFile {{ {} stored values }}", self.stored.len())
    }
}

impl MerlFile {
    /// Wraps stored values: 3 x [`CELLS`] finite f64.
    pub fn from_stored(stored: Vec<f64>) -> Result<Self> {
        if stored.len() != 3 * CELLS {
            return Err(DataError::Invalid(format!(
                "a MERL file holds {} values, got {}",
                3 * CELLS,
                stored.len()
            )));
        }
        if let Some(i) = stored.iter().position(|v| !v.is_finite()) {
            return Err(DataError::Invalid(format!(
                "stored value {i} is {} (not finite)",
                stored[i]
            )));
        }
        Ok(Self { stored })
    }

    /// The stored values, R, G, B blocks in MERL order.
    pub fn stored(&self) -> &[f64] {
        &self.stored
    }

    /// Reads a MERL `.binary` file, keeping the stored values exactly.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = read_checked(path)?;
        let stored = parse_values(path, &bytes, |_, v| v)?;
        Ok(Self { stored })
    }

    /// Parses the bytes of a whole MERL file (what [`MerlFile::read`] reads from disk); `origin`
    /// names the source in errors.
    pub fn from_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let mut header = [0u8; HEADER_BYTES];
        if let Some(h) = bytes.get(..HEADER_BYTES) {
            header.copy_from_slice(h);
        }
        check_header(origin, &header, bytes.len() as u64)?;
        let stored = parse_values(origin, &bytes[HEADER_BYTES..], |_, v| v)?;
        Ok(Self { stored })
    }

    /// Writes the file atomically (temporary file in the same directory, then rename).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &encode(self.stored.iter().copied()))
    }

    /// The table in physical units: stored value x [`MERL_SCALE`], as f32; negative stored values
    /// become [`INVALID_VALUE`]. Fails if a value overflows f32.
    pub fn to_table(&self) -> Result<MerlTable> {
        let values: Vec<f32> =
            self.stored.iter().enumerate().map(|(i, &v)| physical(i / CELLS, v)).collect();
        MerlTable::from_values(values)
    }

    /// The stored values of a table: physical value / [`MERL_SCALE`]; invalid (negative) values
    /// are stored as [`INVALID_STORED`].
    pub fn from_table(table: &MerlTable) -> Self {
        Self {
            stored: table.values().iter().enumerate().map(|(i, &v)| stored(i / CELLS, v)).collect(),
        }
    }
}

/// Reads a MERL `.binary` file as a table in physical units (1/sr, f32).
///
/// Errors name the file: missing path, directory, empty or truncated file, header dimensions
/// other than 90 x 90 x 180, trailing bytes, NaN or infinite values, values too large for f32.
pub fn read_merl(path: impl AsRef<Path>) -> Result<MerlTable> {
    let path = path.as_ref();
    let bytes = read_checked(path)?;
    let values = parse_values(path, &bytes, physical)?;
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(DataError::format(
            path,
            format!("{}: too large for f32 reflectance", describe(i)),
        ));
    }
    MerlTable::from_values(values).map_err(|e| DataError::format(path, e.to_string()))
}

/// Writes a table as a MERL `.binary` file, atomically. Invalid (negative) values are stored
/// as [`INVALID_STORED`]; reading the file back gives a bit-identical table when the table's
/// invalid values are [`INVALID_VALUE`] (as in every table this crate reads or builds).
pub fn write_merl(table: &MerlTable, path: impl AsRef<Path>) -> Result<()> {
    write_atomic(path.as_ref(), &merl_bytes(table))
}

/// The bytes of the MERL `.binary` file of a table ([`FILE_BYTES`] of them), as [`write_merl`]
/// writes them (for a download, say).
pub fn merl_bytes(table: &MerlTable) -> Vec<u8> {
    encode(table.values().iter().enumerate().map(|(i, &v)| stored(i / CELLS, v)))
}

impl MerlTable {
    /// Reads a MERL `.binary` file; see [`read_merl`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        read_merl(path)
    }

    /// Writes a MERL `.binary` file atomically; see [`write_merl`].
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        write_merl(self, path)
    }
}

/// Physical value (1/sr, f32) of a stored value in channel `c`.
#[inline]
fn physical(c: usize, stored: f64) -> f32 {
    if stored < 0.0 {
        INVALID_VALUE
    } else {
        (stored * MERL_SCALE[c]) as f32
    }
}

/// Stored value of a physical value in channel `c`. Exact inverse of [`physical`] for valid
/// values: the f64 division and multiplication err by far less than half an f32 ulp.
#[inline]
fn stored(c: usize, physical: f32) -> f64 {
    if physical < 0.0 {
        INVALID_STORED
    } else {
        f64::from(physical) / MERL_SCALE[c]
    }
}

/// "channel, cell (theta_h, theta_d, phi_d)" of a flat value index, for messages.
fn describe(i: usize) -> String {
    let (h, d, p) = super::grid::cell_coords(i % CELLS);
    let channel = ["red", "green", "blue"][i / CELLS];
    format!("{channel} value at theta_h {h}, theta_d {d}, phi_d {p}")
}

/// Reads the whole file after checking its header and its exact length.
fn read_checked(path: &Path) -> Result<Vec<u8>> {
    let (mut file, len) = open_regular(path)?;
    let mut header = [0u8; HEADER_BYTES];
    if len >= HEADER_BYTES as u64 {
        file.read_exact(&mut header).map_err(|e| DataError::io(path, e))?;
    }
    check_header(path, &header, len)?;
    read_exactly(&mut file, path, FILE_BYTES - HEADER_BYTES)
}

/// Checks a MERL header (the first [`HEADER_BYTES`] of a file of `len` bytes; ignored when the
/// file is shorter) and the file's exact length.
fn check_header(path: &Path, header: &[u8; HEADER_BYTES], len: u64) -> Result<()> {
    if len == 0 {
        return Err(DataError::format(path, "empty file, expected a MERL .binary BRDF"));
    }
    if len < HEADER_BYTES as u64 {
        return Err(DataError::format(
            path,
            format!("truncated: {len} bytes, shorter than the {HEADER_BYTES}-byte MERL header"),
        ));
    }
    let dims: Vec<i32> =
        header.chunks_exact(4).map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    if dims != DIMS {
        return Err(DataError::format(
            path,
            format!(
                "header gives dimensions {} x {} x {}, a MERL BRDF has {} x {} x {} \
                 (not a MERL .binary file, or another resolution)",
                dims[0], dims[1], dims[2], DIMS[0], DIMS[1], DIMS[2]
            ),
        ));
    }
    if len < FILE_BYTES as u64 {
        return Err(DataError::format(
            path,
            format!("truncated: {len} bytes, a MERL file has {FILE_BYTES}"),
        ));
    }
    if len > FILE_BYTES as u64 {
        return Err(DataError::format(
            path,
            format!(
                "{} trailing bytes after the {FILE_BYTES} of a MERL file",
                len - FILE_BYTES as u64
            ),
        ));
    }
    Ok(())
}

/// Parses the 3 x [`CELLS`] f64 values of a MERL file's body with `convert(channel, stored)`,
/// rejecting NaN and infinite stored values.
fn parse_values<T>(path: &Path, body: &[u8], convert: impl Fn(usize, f64) -> T) -> Result<Vec<T>> {
    debug_assert_eq!(body.len(), 8 * 3 * CELLS);
    let mut out = Vec::with_capacity(3 * CELLS);
    let mut all_finite = true;
    for (c, block) in body.chunks_exact(8 * CELLS).enumerate() {
        for b in block.chunks_exact(8) {
            let v = f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
            all_finite &= v.is_finite();
            out.push(convert(c, v));
        }
    }
    if !all_finite {
        let i = body
            .chunks_exact(8)
            .position(|b| {
                !f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]).is_finite()
            })
            .unwrap_or(0);
        let b = &body[8 * i..8 * i + 8];
        let v = f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
        return Err(DataError::format(path, format!("{} is {v} (not finite)", describe(i))));
    }
    Ok(out)
}

/// The bytes of a MERL file holding `stored` (3 x [`CELLS`] values).
fn encode(stored: impl ExactSizeIterator<Item = f64>) -> Vec<u8> {
    debug_assert_eq!(stored.len(), 3 * CELLS);
    let mut bytes = Vec::with_capacity(FILE_BYTES);
    for d in DIMS {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    for v in stored {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::cell_index;

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    /// A table with a distinct, irregular value in every valid cell and channel.
    fn sample_table() -> MerlTable {
        MerlTable::from_fn(|h, d, p| {
            let x = (h * 8100 + d * 90 + p) as f32;
            [x * 1e-4, (x * 0.37).sin().abs() * 3.0, 1.0 / (1.0 + x)]
        })
    }

    /// The bytes of a valid file with stored values `f(i)`.
    fn file_bytes(f: impl Fn(usize) -> f64) -> Vec<u8> {
        encode((0..3 * CELLS).map(f))
    }

    #[test]
    fn raw_file_round_trip_is_byte_identical() -> TestResult {
        let dir = tempfile::tempdir()?;
        let a = dir.path().join("a.binary");
        // Irregular stored values, including negative (invalid), -0.0, tiny and huge ones.
        let bytes = file_bytes(|i| match i % 5 {
            0 => -1.0,
            1 => -0.0,
            2 => 5e-300,
            3 => 1e30 * (i as f64).sqrt(),
            _ => (i as f64 * 0.123).sin(),
        });
        std::fs::write(&a, &bytes)?;
        let file = MerlFile::read(&a)?;
        let b = dir.path().join("b.binary");
        file.write(&b)?;
        assert_eq!(std::fs::read(&b)?, bytes);
        Ok(())
    }

    #[test]
    fn table_round_trip_is_bit_identical() -> TestResult {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("t.binary");
        let table = sample_table();
        table.write(&path)?;
        assert_eq!(std::fs::metadata(&path)?.len(), 34_992_012);
        let back = MerlTable::read(&path)?;
        let same_bits =
            table.values().iter().zip(back.values()).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same_bits);
        // And the raw file agrees with the physical table through the colour scales.
        let raw = MerlFile::read(&path)?;
        let cell = cell_index(30, 40, 50);
        for (c, scale) in MERL_SCALE.iter().enumerate() {
            let s = raw.stored()[c * CELLS + cell];
            assert_eq!((s * scale) as f32, table.values()[c * CELLS + cell]);
        }
        assert_eq!(raw.to_table()?, table);
        assert_eq!(MerlFile::from_table(&table), raw);
        Ok(())
    }

    #[test]
    fn colour_scales_are_merls() {
        // BRDFRead.cpp: RED_SCALE 1.0/1500.0, GREEN_SCALE 1.15/1500.0, BLUE_SCALE 1.66/1500.0.
        assert_eq!(physical(0, 1500.0), 1.0);
        assert_eq!(physical(1, 1500.0), 1.15);
        assert_eq!(physical(2, 1500.0), 1.66);
        assert_eq!(physical(1, -3.0), INVALID_VALUE);
        assert_eq!(stored(2, -0.5), INVALID_STORED);
    }

    fn expect_error(bytes: &[u8], what: &str) -> TestResult {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("bad.binary");
        std::fs::write(&path, bytes)?;
        for msg in [
            read_merl(&path).err().map(|e| e.to_string()),
            MerlFile::read(&path).err().map(|e| e.to_string()),
        ] {
            let msg = msg.unwrap_or_default();
            assert!(msg.contains("bad.binary") && msg.contains(what), "expected {what}: {msg}");
        }
        Ok(())
    }

    fn header(dims: [i32; 3]) -> Vec<u8> {
        dims.iter().flat_map(|d| d.to_le_bytes()).collect()
    }

    #[test]
    fn bad_inputs_are_errors_naming_the_file() -> TestResult {
        let good = file_bytes(|i| (i % 100) as f64);
        expect_error(&[], "empty")?;
        expect_error(&good[..7], "truncated: 7 bytes")?;
        expect_error(&good[..12], "truncated: 12 bytes")?;
        expect_error(&good[..FILE_BYTES - 1], "truncated")?;
        let mut long = good.clone();
        long.extend_from_slice(&[0; 8]);
        expect_error(&long, "8 trailing bytes")?;
        // Other dimensions: checked before anything is allocated from them.
        expect_error(&header([90, 90, 360]), "90 x 90 x 360")?;
        expect_error(&header([90, 1 << 30, 180]), "1073741824")?;
        expect_error(&header([-90, 90, 180]), "-90 x 90 x 180")?;
        let mut other = header([90, 90, 360]);
        other.extend_from_slice(&good[12..]);
        expect_error(&other, "90 x 90 x 360")?;
        expect_error(b"P6\n512 512\n255\n not a BRDF at all", "dimensions")?;
        for (bad, name) in [(f64::NAN, "NaN"), (f64::INFINITY, "inf"), (f64::NEG_INFINITY, "-inf")]
        {
            let mut b = good.clone();
            let i = CELLS + cell_index(1, 2, 3);
            b[12 + 8 * i..20 + 8 * i].copy_from_slice(&bad.to_le_bytes());
            expect_error(&b, &format!("green value at theta_h 1, theta_d 2, phi_d 3 is {name}"))?;
        }
        // Finite in f64 but not in f32 reflectance.
        let mut b = good.clone();
        b[12..20].copy_from_slice(&1e300f64.to_le_bytes());
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("huge.binary");
        std::fs::write(&path, &b)?;
        let msg = read_merl(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("huge.binary") && msg.contains("too large"), "{msg}");
        Ok(())
    }

    #[test]
    fn directory_and_missing_path() -> TestResult {
        let dir = tempfile::tempdir()?;
        let msg = read_merl(dir.path()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("is a directory"), "{msg}");
        let missing = dir.path().join("nothing.binary");
        let msg = read_merl(&missing).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("nothing.binary"), "{msg}");
        // Writing over a directory is refused and leaves it alone.
        assert!(sample_table().write(dir.path()).is_err());
        assert!(dir.path().is_dir());
        Ok(())
    }

    #[test]
    fn failed_write_keeps_the_old_file() -> TestResult {
        let dir = tempfile::tempdir()?;
        let path = dir.path().join("keep.binary");
        let table = sample_table();
        table.write(&path)?;
        // Writing into a missing directory fails and does not touch anything else.
        assert!(table.write(dir.path().join("missing").join("x.binary")).is_err());
        assert_eq!(MerlTable::read(&path)?, table);
        Ok(())
    }

    #[test]
    fn mutated_files_are_rejected_or_read_never_a_panic() {
        use crate::testing::mutate::{fuzz, inputs, Focus};
        let full = file_bytes(|i| if i % 7 == 0 { -1.0 } else { (i as f64 * 1e-3).sin().abs() });
        // A header plus a short stretch of body: mutants of it exercise the header, size and
        // truncation checks without copying 35 MB each; one seed in 100 is the whole file, whose
        // mutants reach the body's NaN/infinity and overflow checks.
        let short = full[..HEADER_BYTES + 4096].to_vec();
        let mut corpus = vec![short; 99];
        corpus.push(full);
        let n = inputs(300);
        let origin = Path::new("fuzz.binary");
        let report =
            fuzz(&corpus, 2026, n, Focus { header: HEADER_BYTES, header_share: 0.9 }, |b| {
                MerlFile::from_bytes(b, origin).and_then(|f| f.to_table())
            });
        eprintln!("MERL reader: {report:?}");
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert_eq!(report.accepted + report.rejected, n);
    }
}

//! The table of SHA-256 digests and sizes that every downloaded MERL file is checked against.
//!
//! Format (tab-separated, UTF-8, one material per line, header first):
//!
//! ```text
//! material<TAB>sha256<TAB>size
//! alum-bronze<TAB>d6506c69…bd37d<TAB>34992012
//! ```
//!
//! Parsing is strict: the header must be exactly `material`, `sha256`, `size`; every line has
//! three fields; names are ASCII letters, digits, `-`, `_` or `.` (not leading `.`), so a name can
//! never leave the output folder or change a URL's path; digests are 64 hexadecimal digits; sizes
//! are positive and at most [`MAX_FILE_SIZE`]; no name appears twice. Each problem is reported
//! with its line number.
use crate::{DataError, Result};
use std::path::{Path, PathBuf};

/// The digests of the 100 files of the MERL BRDF database (Matusik et al. 2003), bundled.
const BUNDLED_MERL: &str = include_str!("../../assets/merl-sha256.tsv");

/// The name under which errors in the bundled table are reported.
const BUNDLED_NAME: &str = "<bundled>/merl-sha256.tsv";

/// The exact header line of a checksum table.
pub const HEADER: [&str; 3] = ["material", "sha256", "size"];

/// The largest file size a table may announce (1 GiB; a MERL file has 34,992,012 bytes), so a
/// corrupt table cannot make the downloader accept an absurd amount of data.
pub const MAX_FILE_SIZE: u64 = 1 << 30;

/// One material: its name (the file is `NAME.binary`), SHA-256 digest and size in bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChecksumEntry {
    pub material: String,
    pub sha256: [u8; 32],
    pub size: u64,
}

impl ChecksumEntry {
    /// The file name of this material, `NAME.binary`.
    pub fn file_name(&self) -> String {
        format!("{}.binary", self.material)
    }

    /// The digest as 64 lowercase hexadecimal digits.
    pub fn sha256_hex(&self) -> String {
        hex::encode(self.sha256)
    }
}

/// A parsed checksum table, in file order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChecksumTable {
    entries: Vec<ChecksumEntry>,
}

impl ChecksumTable {
    /// The bundled table of the official MERL database (100 materials).
    pub fn bundled_merl() -> Result<Self> {
        Self::parse(BUNDLED_MERL, Path::new(BUNDLED_NAME))
    }

    /// Reads a table from `path` (same format as the bundled one).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| DataError::io(path, e))?;
        Self::parse(&text, path)
    }

    /// Parses `text`; `origin` names the file in error messages.
    pub fn parse(text: &str, origin: &Path) -> Result<Self> {
        let bad = |line: usize, problem: String| {
            DataError::format(PathBuf::from(origin), format!("line {line}: {problem}"))
        };
        let mut lines =
            text.split('\n').enumerate().map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)));
        let Some((_, header)) = lines.next().filter(|(_, h)| !h.is_empty()) else {
            return Err(DataError::format(
                origin,
                "empty checksum table (expected the header `material\\tsha256\\tsize`)",
            ));
        };
        if header.split('\t').collect::<Vec<_>>() != HEADER {
            return Err(bad(
                1,
                format!("header is {header:?}, expected \"material\\tsha256\\tsize\""),
            ));
        }
        let mut entries: Vec<ChecksumEntry> = Vec::new();
        let mut blank_at = None;
        for (number, line) in lines {
            if line.is_empty() {
                blank_at.get_or_insert(number);
                continue;
            }
            if let Some(blank) = blank_at {
                return Err(bad(blank, "blank line inside the table".into()));
            }
            let fields: Vec<&str> = line.split('\t').collect();
            let [material, digest, size] = fields[..] else {
                return Err(bad(
                    number,
                    format!(
                        "{} tab-separated fields, expected 3 (material, sha256, size)",
                        fields.len()
                    ),
                ));
            };
            check_name(material).map_err(|p| bad(number, p))?;
            let sha256 = parse_digest(digest)
                .map_err(|p| bad(number, format!("material {material}: {p}")))?;
            let size =
                parse_size(size).map_err(|p| bad(number, format!("material {material}: {p}")))?;
            if entries.iter().any(|e| e.material == material) {
                return Err(bad(number, format!("material {material} appears twice")));
            }
            entries.push(ChecksumEntry { material: material.to_string(), sha256, size });
        }
        if entries.is_empty() {
            return Err(DataError::format(origin, "the checksum table lists no materials"));
        }
        Ok(Self { entries })
    }

    /// All entries, in table order.
    pub fn entries(&self) -> &[ChecksumEntry] {
        &self.entries
    }

    /// The entry of `material`, if listed.
    pub fn get(&self, material: &str) -> Option<&ChecksumEntry> {
        self.entries.iter().find(|e| e.material == material)
    }

    /// The entries of `materials` in the order given (all entries when `None`); an unknown name
    /// or a repeated one is an error.
    pub fn select(&self, materials: Option<&[String]>) -> Result<Vec<&ChecksumEntry>> {
        let Some(names) = materials else {
            return Ok(self.entries.iter().collect());
        };
        if names.is_empty() {
            return Err(DataError::Invalid("no materials selected".into()));
        }
        let mut chosen: Vec<&ChecksumEntry> = Vec::with_capacity(names.len());
        for name in names {
            let entry = self.get(name).ok_or_else(|| {
                DataError::Invalid(format!(
                    "material {name:?} is not in the checksum table ({} materials, e.g. {})",
                    self.entries.len(),
                    self.entries
                        .iter()
                        .take(3)
                        .map(|e| e.material.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            if chosen.iter().any(|c| c.material == entry.material) {
                return Err(DataError::Invalid(format!("material {name:?} is selected twice")));
            }
            chosen.push(entry);
        }
        Ok(chosen)
    }
}

/// Checks that `name` is safe as a file name and as a URL path segment.
fn check_name(name: &str) -> std::result::Result<(), String> {
    if name.is_empty() {
        return Err("empty material name".into());
    }
    if name.starts_with('.') {
        return Err(format!("material name {name:?} starts with '.'"));
    }
    if let Some(c) =
        name.chars().find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.')))
    {
        return Err(format!(
            "material name {name:?} contains {c:?} (allowed: ASCII letters, digits, '-', '_', '.')"
        ));
    }
    Ok(())
}

/// Parses 64 hexadecimal digits (either case).
fn parse_digest(digest: &str) -> std::result::Result<[u8; 32], String> {
    if digest.len() != 64 {
        return Err(format!(
            "sha256 {digest:?} has {} characters, expected 64 hexadecimal digits",
            digest.len()
        ));
    }
    let mut out = [0u8; 32];
    hex::decode_to_slice(digest, &mut out)
        .map_err(|e| format!("sha256 {digest:?} is not hexadecimal: {e}"))?;
    Ok(out)
}

/// Parses a positive decimal size of at most [`MAX_FILE_SIZE`].
fn parse_size(size: &str) -> std::result::Result<u64, String> {
    if size.is_empty() || !size.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("size {size:?} is not a decimal number of bytes"));
    }
    match size.parse::<u64>() {
        Ok(0) => Err("size is 0".into()),
        Ok(n) if n <= MAX_FILE_SIZE => Ok(n),
        _ => Err(format!("size {size} exceeds the limit of {MAX_FILE_SIZE} bytes")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DIGEST_A: &str = "d6506c69e44430bfe8ea676f3950599ca3a6bfb1f46b9906da336d13991bd37d";

    fn parse(text: &str) -> Result<ChecksumTable> {
        ChecksumTable::parse(text, Path::new("table.tsv"))
    }

    fn message(text: &str) -> String {
        match parse(text) {
            Ok(t) => panic!("accepted a bad table: {t:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bundled_table_lists_the_100_merl_materials() {
        let table = ChecksumTable::bundled_merl().expect("bundled table parses");
        assert_eq!(table.entries().len(), 100);
        // Every MERL file has the same size: 12-byte header + 3 * 90*90*180 f64 values.
        assert!(table.entries().iter().all(|e| e.size == 12 + 3 * 90 * 90 * 180 * 8));
        let bronze = table.get("alum-bronze").expect("alum-bronze listed");
        assert_eq!(bronze.sha256_hex(), DIGEST_A);
        assert_eq!(bronze.file_name(), "alum-bronze.binary");
        assert!(table.get("yellow-plastic").is_some());
    }

    #[test]
    fn parses_a_good_table_with_crlf_and_trailing_newline() {
        let upper = DIGEST_A.to_uppercase();
        let text =
            format!("material\tsha256\tsize\r\na\t{DIGEST_A}\t10\r\nb-2_x.y\t{upper}\t1\n\n");
        let table = parse(&text).expect("parses");
        assert_eq!(table.entries().len(), 2);
        assert_eq!(table.entries()[1].material, "b-2_x.y");
        assert_eq!(table.entries()[1].sha256_hex(), DIGEST_A);
        assert_eq!(table.entries()[0].size, 10);
    }

    #[test]
    fn rejects_bad_lines_with_their_line_numbers() {
        let head = "material\tsha256\tsize\n";
        let good = format!("a\t{DIGEST_A}\t10\n");
        let cases: Vec<(String, &str)> = vec![
            (format!("{head}{good}b\t{DIGEST_A}\n"), "line 3: 2 tab-separated fields"),
            (format!("{head}{good}b\t{DIGEST_A}\t10\textra\n"), "line 3: 4 tab-separated fields"),
            (format!("{head}b\t{}\t10\n", &DIGEST_A[..63]), "line 2: material b: sha256"),
            (format!("{head}b\t{}zz\t10\n", &DIGEST_A[..62]), "not hexadecimal"),
            (format!("{head}{good}b\t{DIGEST_A}\t-5\n"), "line 3: material b: size \"-5\""),
            (format!("{head}b\t{DIGEST_A}\t0\n"), "line 2: material b: size is 0"),
            (format!("{head}b\t{DIGEST_A}\t99999999999999999999999\n"), "exceeds the limit"),
            (format!("{head}b\t{DIGEST_A}\t{}\n", MAX_FILE_SIZE + 1), "exceeds the limit"),
            (format!("{head}{good}a\t{DIGEST_A}\t10\n"), "line 3: material a appears twice"),
            (
                format!("{head}../etc\t{DIGEST_A}\t10\n"),
                "line 2: material name \"../etc\" starts with '.'",
            ),
            (format!("{head}a/b\t{DIGEST_A}\t10\n"), "contains '/'"),
            (format!("{head}\t{DIGEST_A}\t10\n"), "line 2: empty material name"),
            (format!("{head}{good}\n{good}"), "line 3: blank line inside the table"),
            (format!("material,sha256,size\n{good}"), "line 1: header"),
            (format!("sha256\tmaterial\tsize\n{good}"), "line 1: header"),
            (head.to_string(), "lists no materials"),
            (String::new(), "empty checksum table"),
        ];
        for (text, needle) in cases {
            let msg = message(&text);
            assert!(msg.starts_with("table.tsv: "), "error does not name the file: {msg}");
            assert!(msg.contains(needle), "error {msg:?} lacks {needle:?} for table {text:?}");
        }
    }

    #[test]
    fn select_keeps_order_and_rejects_unknown_or_repeated_names() {
        let text = format!(
            "material\tsha256\tsize\na\t{DIGEST_A}\t1\nb\t{DIGEST_A}\t2\nc\t{DIGEST_A}\t3\n"
        );
        let table = parse(&text).expect("parses");
        assert_eq!(table.select(None).expect("all").len(), 3);
        let names = vec!["c".to_string(), "a".to_string()];
        let chosen = table.select(Some(&names)).expect("subset");
        assert_eq!(chosen.iter().map(|e| e.material.as_str()).collect::<Vec<_>>(), ["c", "a"]);
        let unknown = vec!["zz".to_string()];
        assert!(table
            .select(Some(&unknown))
            .unwrap_err()
            .to_string()
            .contains("\"zz\" is not in the checksum table"));
        let twice = vec!["a".to_string(), "a".to_string()];
        assert!(table.select(Some(&twice)).unwrap_err().to_string().contains("selected twice"));
        assert!(table.select(Some(&[])).is_err());
    }

    #[test]
    fn read_names_a_missing_file() {
        let msg =
            ChecksumTable::read(Path::new("/nonexistent/dir/sums.tsv")).unwrap_err().to_string();
        assert!(msg.contains("/nonexistent/dir/sums.tsv"), "{msg}");
    }
}

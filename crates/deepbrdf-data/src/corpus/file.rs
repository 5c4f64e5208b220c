//! The corpus file: a seed, a count and one parameter record per material, as JSON lines
//! (`corpus.jsonl`, about 0.5 KB per material). The first line is the [`Header`]; line `i + 2`
//! is the [`Record`] of material `i`: its index, its [`Material`] and its known attributes.
//! Tables are not stored: they are regenerated from the parameters ([`Material::table`]), the
//! same bits on every machine. The file is written atomically and read as a stream (one line at
//! a time, each at most [`MAX_LINE`] bytes), so a corpus is never held in memory whole.

use super::attributes::KnownAttributes;
use super::material::Material;
use super::sampler::sample;
use crate::error::{DataError, Result};
use crate::files::write_atomic_with;
use crate::Progress;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// The `format` of a corpus file's header.
pub const FORMAT: &str = "deepbrdf-corpus";
/// The version of the format this crate writes and reads.
pub const VERSION: u32 = 1;
/// Longest line a reader accepts (a record is under 1 KB).
pub const MAX_LINE: usize = 64 * 1024;
/// Materials sampled and serialised per parallel batch when writing.
const WRITE_BATCH: u64 = 4096;

/// The first line of a corpus file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Header {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The sampler's seed ([`super::sampler::sample`]).
    pub seed: u64,
    /// Number of records.
    pub count: u64,
}

/// One material of a corpus.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// The material's index in the corpus (0-based, consecutive).
    pub index: u64,
    /// Its known attributes ([`Material::attributes`]), for readers without this crate.
    pub attributes: KnownAttributes,
    /// Its parameters.
    pub material: Material,
}

impl Record {
    /// The record of material `index` of the corpus of `seed`.
    pub fn sampled(seed: u64, index: u64) -> Record {
        let material = sample(seed, index);
        Record { index, attributes: material.attributes(), material }
    }
}

/// Writes the corpus of `seed` with `count` materials to `path` atomically (in parallel batches,
/// streamed to disk); returns the file's size in bytes.
pub fn write_corpus(path: &Path, seed: u64, count: u64, progress: &dyn Progress) -> Result<u64> {
    let header = Header { format: FORMAT.into(), version: VERSION, seed, count };
    let mut bytes = 0u64;
    progress.start(count, "sampling the corpus");
    let written = write_atomic_with(path, |out, tmp| {
        let mut put = |line: String| {
            bytes += line.len() as u64 + 1;
            out.write_all(line.as_bytes())
                .and_then(|()| out.write_all(b"\n"))
                .map_err(|e| DataError::io(tmp, e))
        };
        put(to_json(&header)?)?;
        for start in (0..count).step_by(WRITE_BATCH as usize) {
            let end = (start + WRITE_BATCH).min(count);
            let lines: Vec<Result<String>> =
                (start..end).into_par_iter().map(|i| to_json(&Record::sampled(seed, i))).collect();
            for line in lines {
                put(line?)?;
            }
            progress.advance(end - start);
        }
        Ok(())
    });
    progress.finish();
    written.map(|()| bytes)
}

fn to_json(value: &impl Serialize) -> Result<String> {
    serde_json::to_string(value)
        .map_err(|e| DataError::Invalid(format!("serialising a corpus record: {e}")))
}

/// Reads a corpus file one record at a time. Each record is checked: its index is the next one,
/// its material valid and its attributes those of its material; the file holds exactly the
/// header's count. Errors name the file and the line; after one, the iterator ends.
pub struct CorpusReader {
    path: PathBuf,
    reader: BufReader<File>,
    header: Header,
    /// Index of the next record.
    next: u64,
    /// Line number of the next line (1-based).
    line: u64,
    done: bool,
}

impl CorpusReader {
    /// Opens `path` and reads its header.
    pub fn open(path: &Path) -> Result<Self> {
        let (file, _) = crate::files::open_regular(path)?;
        let mut reader = Self {
            path: path.to_path_buf(),
            reader: BufReader::new(file),
            header: Header { format: String::new(), version: 0, seed: 0, count: 0 },
            next: 0,
            line: 1,
            done: false,
        };
        let first = reader
            .next_line()?
            .ok_or_else(|| DataError::format(path, "empty: no corpus header"))?;
        let header: Header = serde_json::from_str(&first)
            .map_err(|e| reader.error(format!("not a corpus header ({e})")))?;
        if header.format != FORMAT || header.version != VERSION {
            return Err(reader.error(format!(
                "format {} version {}, expected {FORMAT} version {VERSION}",
                header.format, header.version
            )));
        }
        reader.header = header;
        reader.line = 2;
        Ok(reader)
    }

    /// The file's header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// An error at the current line.
    fn error(&self, problem: String) -> DataError {
        DataError::format(&self.path, format!("line {}: {problem}", self.line))
    }

    /// The next line without its newline, `None` at the end of the file.
    fn next_line(&mut self) -> Result<Option<String>> {
        let mut buf = Vec::new();
        let limit = MAX_LINE as u64 + 1;
        let n = (&mut self.reader)
            .take(limit)
            .read_until(b'\n', &mut buf)
            .map_err(|e| DataError::io(&self.path, e))?;
        if n == 0 {
            return Ok(None);
        }
        if buf.last() == Some(&b'\n') {
            buf.pop();
        } else if n as u64 == limit {
            return Err(self.error(format!("longer than {MAX_LINE} bytes")));
        }
        String::from_utf8(buf).map(Some).map_err(|_| self.error("not UTF-8".into()))
    }

    fn read_record(&mut self) -> Result<Option<Record>> {
        let line = self.next_line()?;
        let count = self.header.count;
        let Some(line) = line else {
            return match self.next < count {
                true => Err(DataError::format(
                    &self.path,
                    format!("truncated: {} of {count} records", self.next),
                )),
                false => Ok(None),
            };
        };
        if self.next >= count {
            return Err(self.error(format!("more records than the header's count {count}")));
        }
        let record: Record = serde_json::from_str(&line)
            .map_err(|e| self.error(format!("not a corpus record ({e})")))?;
        if record.index != self.next {
            return Err(
                self.error(format!("record index {}, expected {}", record.index, self.next))
            );
        }
        record.material.validate().map_err(|e| self.error(e.to_string()))?;
        let (stored, computed) =
            (record.attributes.to_array(), record.material.attributes().to_array());
        if stored.iter().zip(computed).any(|(s, c)| (s - c).abs() > 1e-12 * c.abs().max(1.0)) {
            return Err(
                self.error(format!("attributes {stored:?} are not the material's {computed:?}"))
            );
        }
        self.next += 1;
        self.line += 1;
        Ok(Some(record))
    }
}

impl Iterator for CorpusReader {
    type Item = Result<Record>;

    fn next(&mut self) -> Option<Result<Record>> {
        if self.done {
            return None;
        }
        let item = self.read_record().transpose();
        self.done = !matches!(item, Some(Ok(_)));
        item
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Silent;

    #[test]
    fn a_written_corpus_reads_back_record_for_record() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("corpus.jsonl");
        let bytes = write_corpus(&path, 3, 40, &Silent).expect("write");
        assert_eq!(bytes, std::fs::metadata(&path).expect("written").len());
        assert!(bytes / 40 < 1024, "{} bytes per material", bytes / 40);
        let reader = CorpusReader::open(&path).expect("open");
        assert_eq!(
            reader.header(),
            &Header { format: FORMAT.into(), version: VERSION, seed: 3, count: 40 }
        );
        let records: Vec<Record> = reader.collect::<Result<_>>().expect("read");
        let expected: Vec<Record> = (0..40).map(|i| Record::sampled(3, i)).collect();
        assert_eq!(records, expected);
        // Deterministic to the byte.
        let again = dir.path().join("again.jsonl");
        write_corpus(&again, 3, 40, &Silent).expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), std::fs::read(&again).expect("read"));
    }

    #[test]
    fn damaged_corpora_are_refused_with_file_and_line() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("corpus.jsonl");
        write_corpus(&path, 1, 3, &Silent).expect("write");
        let text = std::fs::read_to_string(&path).expect("read");
        let lines: Vec<&str> = text.lines().collect();
        let bad_index = lines[2].replacen("\"index\":1", "\"index\":7", 1);
        let bad_attributes = lines[1].replacen("\"roughness\":", "\"roughness\":0.5e-9+", 1);
        let long = "x".repeat(MAX_LINE + 10);
        let header_count_2 = lines[0].replace("\"count\":3", "\"count\":2");
        let cases: Vec<(String, &str)> = vec![
            (String::new(), "empty"),
            (
                "{\"format\":\"other\",\"version\":1,\"seed\":0,\"count\":0}\n".into(),
                "format other",
            ),
            (lines[..3].join("\n"), "truncated: 2 of 3"),
            ([lines[0], lines[1], &bad_index, lines[3]].join("\n"), "line 3: record index 7"),
            ([lines[0], &bad_attributes].join("\n"), "line 2: not a corpus record"),
            ([lines[0], lines[1], &long].join("\n"), "line 3: longer than"),
            ([&header_count_2, lines[1], lines[2], lines[3]].join("\n"), "line 4: more records"),
        ];
        for (content, needle) in cases {
            std::fs::write(&path, &content).expect("write");
            let err = CorpusReader::open(&path)
                .and_then(|r| r.collect::<Result<Vec<_>>>())
                .expect_err(needle)
                .to_string();
            assert!(err.contains("corpus.jsonl") && err.contains(needle), "{needle}: {err}");
        }
        // A record whose material is out of range.
        let bad = lines[1].replacen("\"alpha\":", "\"alpha\":-", 1);
        if bad != lines[1] {
            std::fs::write(&path, [lines[0], &bad, lines[2], lines[3]].join("\n")).expect("write");
            let err = CorpusReader::open(&path).and_then(|r| r.collect::<Result<Vec<_>>>());
            assert!(err.expect_err("negative alpha").to_string().contains("line 2"));
        }
    }
}

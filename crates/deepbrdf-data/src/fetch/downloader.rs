//! Resumable, verified download of MERL `.binary` files.
//!
//! Each file is written to `NAME.binary.part`, fsynced, checked against the SHA-256 and size of
//! the [`ChecksumTable`](super::ChecksumTable) and only then renamed to `NAME.binary`, so a final
//! name never holds a partial or unverified file. A `.part` left by an interrupted run (or by a
//! dropped connection within this run) is continued with an HTTP `Range: bytes=N-` request; when
//! the server ignores the range (answers 200) the download starts over.
use super::checksums::ChecksumEntry;
use super::error::FetchError;
use super::http::{classify, header, parse_content_range, AttemptError};
use crate::Progress;
use sha2::{Digest, Sha256};
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Where the MERL BRDF database (Matusik et al. 2003) is served: the MIT Computational Design
/// and Fabrication Group's site, which hosts the database's page (`/wojciech/BRDFDatabase`) and
/// files since the CSAIL home pages were retired. The historical location of the same files is
/// [`MERL_LEGACY_BASE_URL`]. MERL provides the data for research and academic use only
/// (<https://www.merl.com/brdf/>).
pub const MERL_BASE_URL: &str = "https://cdfg.mit.edu/assets/files/brdfs/";

/// The historical location of the MERL files (pass it as the base URL if the default fails).
pub const MERL_LEGACY_BASE_URL: &str = "http://people.csail.mit.edu/wojciech/BRDFDatabase/brdfs/";

/// The suffix of a file being downloaded.
pub const PART_SUFFIX: &str = ".part";

/// The suffix given to a mismatching existing file moved aside with [`FetchOptions::force`].
pub const MISMATCH_SUFFIX: &str = ".mismatch";

/// How to download.
#[derive(Debug, Clone)]
pub struct FetchOptions {
    /// Folder URL; file `NAME` is fetched from `{base_url}/NAME.binary`.
    pub base_url: String,
    /// Folder that receives `NAME.binary` (created if missing).
    pub out_dir: PathBuf,
    /// Extra attempts after a transient failure (connection error, timeout, 408/429/5xx, a body
    /// cut short); each resumes where the last stopped.
    pub retries: u32,
    /// Wait before the first retry; doubled for each further one.
    pub retry_wait: Duration,
    /// Limit for connecting and for each read or write on the connection.
    pub timeout: Duration,
    /// Move an existing `NAME.binary` with the wrong content aside (to `NAME.binary.mismatch`)
    /// instead of reporting it.
    pub force: bool,
}

impl FetchOptions {
    /// Defaults for `out_dir`: the official URL, 4 retries from 2 s, 60 s timeout, no force.
    pub fn new(out_dir: impl Into<PathBuf>) -> Self {
        Self {
            base_url: MERL_BASE_URL.to_string(),
            out_dir: out_dir.into(),
            retries: 4,
            retry_wait: Duration::from_secs(2),
            timeout: Duration::from_secs(60),
            force: false,
        }
    }

    /// The URL of `file_name` under [`Self::base_url`].
    pub fn url_of(&self, file_name: &str) -> String {
        format!("{}/{file_name}", self.base_url.trim_end_matches('/'))
    }
}

/// One material that could not be fetched.
#[derive(Debug)]
pub struct FetchFailure {
    pub material: String,
    pub error: FetchError,
}

/// What [`Fetcher::fetch`] did.
#[derive(Debug, Default)]
pub struct FetchReport {
    /// Downloaded and verified.
    pub downloaded: Vec<String>,
    /// Already present with the right digest.
    pub skipped: Vec<String>,
    /// Existing files with the wrong content moved aside (only with `force`).
    pub moved_aside: Vec<PathBuf>,
    /// Failed; the others went on (unless the network failed, see `not_attempted`).
    pub failed: Vec<FetchFailure>,
    /// Not tried because a connection failure persisted through all retries (the server is
    /// probably unreachable); rerun to continue.
    pub not_attempted: Vec<String>,
}

impl FetchReport {
    /// Whether every selected material is now present and verified.
    pub fn is_complete(&self) -> bool {
        self.failed.is_empty() && self.not_attempted.is_empty()
    }
}

/// Downloads MERL files over HTTP(S) (ureq with rustls).
pub struct Fetcher {
    options: FetchOptions,
    agent: ureq::Agent,
}

const CHUNK: usize = 1 << 16;

impl Fetcher {
    pub fn new(options: FetchOptions) -> Self {
        let timeout = Some(options.timeout);
        let agent = ureq::Agent::config_builder()
            .http_status_as_error(false)
            .timeout_connect(timeout)
            .timeout_per_read(timeout)
            .timeout_per_write(timeout)
            .user_agent(concat!("deepbrdf-data/", env!("CARGO_PKG_VERSION")))
            .build()
            .into();
        Self { options, agent }
    }

    pub fn options(&self) -> &FetchOptions {
        &self.options
    }

    /// Makes `entries` present and verified in the output folder. Two progress phases: checking
    /// files already there (bytes hashed), then downloading (bytes received, with the current
    /// file as status). Per-material failures are collected in the report; only a failure to
    /// create the output folder is an `Err`.
    pub fn fetch(
        &self,
        entries: &[&ChecksumEntry],
        progress: &dyn Progress,
    ) -> Result<FetchReport, FetchError> {
        let out = &self.options.out_dir;
        std::fs::create_dir_all(out).map_err(|e| FetchError::io(out, e))?;
        let mut report = FetchReport::default();

        // Phase 1: files already under their final name.
        let existing: Vec<&ChecksumEntry> =
            entries.iter().copied().filter(|e| self.final_path(e).exists()).collect();
        let mut todo: Vec<&ChecksumEntry> =
            entries.iter().copied().filter(|e| !self.final_path(e).exists()).collect();
        if !existing.is_empty() {
            progress.start(existing.iter().map(|e| e.size).sum(), "checking existing files");
            for entry in existing {
                match self.check_existing(entry, progress) {
                    Ok(None) => report.skipped.push(entry.material.clone()),
                    Ok(Some(aside)) => {
                        report.moved_aside.push(aside);
                        todo.push(entry);
                    }
                    Err(error) => {
                        report.failed.push(FetchFailure { material: entry.material.clone(), error })
                    }
                }
            }
            progress.finish();
        }
        // Keep the table's order for downloads.
        todo.sort_by_key(|t| entries.iter().position(|e| e.material == t.material));

        // Phase 2: downloads.
        if !todo.is_empty() {
            progress.start(todo.iter().map(|e| e.size).sum(), "downloading MERL");
            let count = todo.len();
            for (i, entry) in todo.iter().enumerate() {
                progress.status(&format!("[{}/{count}] {}", i + 1, entry.material));
                match self.download(entry, progress, &format!("[{}/{count}]", i + 1)) {
                    Ok(()) => report.downloaded.push(entry.material.clone()),
                    Err(error) => {
                        let unreachable = matches!(error, FetchError::Transport { .. });
                        report
                            .failed
                            .push(FetchFailure { material: entry.material.clone(), error });
                        if unreachable {
                            report.not_attempted =
                                todo[i + 1..].iter().map(|e| e.material.clone()).collect();
                            break;
                        }
                    }
                }
            }
            progress.finish();
        }
        Ok(report)
    }

    fn final_path(&self, entry: &ChecksumEntry) -> PathBuf {
        self.options.out_dir.join(entry.file_name())
    }

    fn part_path(&self, entry: &ChecksumEntry) -> PathBuf {
        self.options.out_dir.join(format!("{}{PART_SUFFIX}", entry.file_name()))
    }

    /// `Ok(None)`: the existing file is correct. `Ok(Some(path))`: it was wrong and, with
    /// `force`, moved to `path`. `Err`: it is wrong and was left alone.
    fn check_existing(
        &self,
        entry: &ChecksumEntry,
        progress: &dyn Progress,
    ) -> Result<Option<PathBuf>, FetchError> {
        let path = self.final_path(entry);
        let meta = std::fs::metadata(&path).map_err(|e| FetchError::io(&path, e))?;
        let detail = if !meta.is_file() {
            progress.advance(entry.size);
            Some("is not a regular file".to_string())
        } else if meta.len() != entry.size {
            progress.advance(entry.size);
            Some(format!("has {} bytes, expected {}", meta.len(), entry.size))
        } else {
            let digest = sha256_file(&path, progress)?;
            (digest != entry.sha256).then(|| {
                format!("its SHA-256 is {}, expected {}", hex::encode(digest), entry.sha256_hex())
            })
        };
        let Some(detail) = detail else { return Ok(None) };
        if !self.options.force {
            return Err(FetchError::Existing { material: entry.material.clone(), path, detail });
        }
        let aside = free_name(&path, MISMATCH_SUFFIX);
        std::fs::rename(&path, &aside).map_err(|e| FetchError::io(&path, e))?;
        Ok(Some(aside))
    }

    /// Downloads one material to its part file (resuming, retrying), verifies it, renames it.
    fn download(
        &self,
        entry: &ChecksumEntry,
        progress: &dyn Progress,
        tag: &str,
    ) -> Result<(), FetchError> {
        let url = self.options.url_of(&entry.file_name());
        let part = self.part_path(entry);
        // Bytes of this file already counted in the overall progress (a restart must not count
        // them twice).
        let mut counted = 0u64;
        let mut attempts = 0u32;
        loop {
            attempts += 1;
            match self.attempt(entry, &url, &part, progress, tag, &mut counted) {
                Ok(()) => break,
                Err(AttemptError::Fatal(error)) => return Err(error),
                Err(AttemptError::Transient(message)) => {
                    if attempts > self.options.retries {
                        return Err(FetchError::Transport { url, message, attempts });
                    }
                    let wait = self.options.retry_wait.saturating_mul(1 << (attempts - 1).min(16));
                    progress.status(&format!(
                        "{tag} {}: {message}; retry {attempts}/{} in {:.0?}",
                        entry.material, self.options.retries, wait
                    ));
                    std::thread::sleep(wait);
                }
            }
        }
        let digest = sha256_file(&part, &crate::Silent)?;
        if digest != entry.sha256 {
            std::fs::remove_file(&part).map_err(|e| FetchError::io(&part, e))?;
            return Err(FetchError::Checksum {
                material: entry.material.clone(),
                part,
                expected: entry.sha256_hex(),
                actual: hex::encode(digest),
            });
        }
        let target = self.final_path(entry);
        std::fs::rename(&part, &target).map_err(|e| FetchError::io(&target, e))?;
        sync_dir(&self.options.out_dir);
        Ok(())
    }

    /// One request: continues the part file from its length, or starts it over.
    fn attempt(
        &self,
        entry: &ChecksumEntry,
        url: &str,
        part: &Path,
        progress: &dyn Progress,
        tag: &str,
        counted: &mut u64,
    ) -> Result<(), AttemptError> {
        let fatal_io = |e: std::io::Error| AttemptError::Fatal(FetchError::io(part, e));
        let mut have = match std::fs::metadata(part) {
            Ok(m) => m.len(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => 0,
            Err(e) => return Err(fatal_io(e)),
        };
        if have > entry.size {
            std::fs::remove_file(part).map_err(fatal_io)?;
            have = 0;
        }
        if have == entry.size {
            return Ok(()); // complete from an earlier run; verified by the caller
        }
        let mut request = self.agent.get(url);
        if have > 0 {
            request = request.header("Range", format!("bytes={have}-"));
        }
        let mut response = request.call().map_err(|e| classify(url, e))?;
        let status = response.status().as_u16();
        let protocol = |problem: String| {
            AttemptError::Fatal(FetchError::Protocol { url: url.to_string(), problem })
        };
        let offset = match status {
            206 => {
                let range = header(&response, "content-range");
                let start = parse_content_range(&range, entry.size).map_err(|p| protocol(p))?;
                if start != have {
                    return Err(protocol(format!(
                        "asked for bytes from {have}, the server sent Content-Range {range:?}"
                    )));
                }
                have
            }
            200 => {
                if let Ok(length) = header(&response, "content-length").parse::<u64>() {
                    if length != entry.size {
                        return Err(protocol(format!(
                            "the server sends {length} bytes, the checksum table says {} for {}",
                            entry.size, entry.material
                        )));
                    }
                }
                0 // no range requested, or the server ignored it: start over
            }
            416 => {
                // Our part file does not fit the server's file: start over.
                std::fs::remove_file(part).map_err(fatal_io)?;
                return Err(AttemptError::Transient(format!(
                    "HTTP 416 for bytes from {have}; restarting"
                )));
            }
            408 | 429 | 500 | 502 | 503 | 504 => {
                return Err(AttemptError::Transient(
                    FetchError::Status { url: url.to_string(), status }.to_string(),
                ));
            }
            _ => {
                return Err(AttemptError::Fatal(FetchError::Status {
                    url: url.to_string(),
                    status,
                }))
            }
        };

        let mut file = OpenOptions::new()
            .create(true)
            .write(true)
            .truncate(false)
            .open(part)
            .map_err(fatal_io)?;
        file.set_len(offset).map_err(fatal_io)?;
        file.seek(SeekFrom::Start(offset)).map_err(fatal_io)?;
        let mut body = response.body_mut().as_reader();
        let mut position = offset;
        let mut buffer = vec![0u8; CHUNK];
        let mut last_status = 0u64;
        let result = loop {
            let n = match body.read(&mut buffer) {
                Ok(0) => break Ok(()),
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    break Err(AttemptError::Transient(format!(
                        "connection lost at byte {position}: {e}"
                    )))
                }
            };
            if position + n as u64 > entry.size {
                break Err(protocol(format!(
                    "the server sends more than the {} bytes the checksum table lists for {}",
                    entry.size, entry.material
                )));
            }
            if let Err(e) = file.write_all(&buffer[..n]) {
                break Err(fatal_io(e));
            }
            position += n as u64;
            if position > *counted {
                progress.advance(position - *counted);
                *counted = position;
            }
            if position - last_status >= 1 << 20 || position == entry.size {
                last_status = position;
                progress.status(&format!(
                    "{tag} {}: {:.1}/{:.1} MiB",
                    entry.material,
                    position as f64 / MIB,
                    entry.size as f64 / MIB
                ));
            }
        };
        // Keep what arrived, durably, whatever happened: the next attempt resumes from it.
        file.sync_all().map_err(fatal_io)?;
        drop(file);
        if let Err(AttemptError::Fatal(FetchError::Protocol { .. })) = &result {
            // Content we cannot trust: do not resume from it.
            let _ = std::fs::remove_file(part);
        }
        result?;
        if position < entry.size {
            return Err(AttemptError::Transient(format!(
                "connection closed after byte {position} of {}",
                entry.size
            )));
        }
        Ok(())
    }
}

const MIB: f64 = 1024.0 * 1024.0;

/// The SHA-256 of a file, reporting bytes read to `progress`.
pub fn sha256_file(path: &Path, progress: &dyn Progress) -> Result<[u8; 32], FetchError> {
    let mut file = File::open(path).map_err(|e| FetchError::io(path, e))?;
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 20];
    loop {
        let n = match file.read(&mut buffer) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(FetchError::io(path, e)),
        };
        hasher.update(&buffer[..n]);
        progress.advance(n as u64);
    }
    Ok(hasher.finalize().into())
}

/// `path` + `suffix`, or with `.1`, `.2`, ... appended until the name is free.
fn free_name(path: &Path, suffix: &str) -> PathBuf {
    let base = format!("{}{suffix}", path.display());
    let mut candidate = PathBuf::from(&base);
    let mut n = 1;
    while candidate.exists() {
        candidate = PathBuf::from(format!("{base}.{n}"));
        n += 1;
    }
    candidate
}

/// Makes a rename in `dir` durable where the platform allows (best effort).
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_join_the_base_and_the_file_name() {
        let mut options = FetchOptions::new("out");
        assert_eq!(options.url_of("a.binary"), "https://cdfg.mit.edu/assets/files/brdfs/a.binary");
        options.base_url = "http://127.0.0.1:9/x".into();
        assert_eq!(options.url_of("a.binary"), "http://127.0.0.1:9/x/a.binary");
    }

    #[test]
    fn free_name_avoids_existing_files() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("a.binary");
        assert_eq!(free_name(&path, ".mismatch"), dir.path().join("a.binary.mismatch"));
        std::fs::write(dir.path().join("a.binary.mismatch"), b"x").expect("write");
        assert_eq!(free_name(&path, ".mismatch"), dir.path().join("a.binary.mismatch.1"));
    }
}

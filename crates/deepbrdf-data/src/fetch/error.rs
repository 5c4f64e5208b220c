//! What can go wrong downloading one MERL file. Every variant names the URL or the file.
use std::path::PathBuf;

/// A failure to download or verify one material.
#[derive(Debug, thiserror::Error)]
pub enum FetchError {
    /// The server answered with an HTTP status other than 200 or 206.
    #[error("GET {url}: HTTP {status}{}", reason_suffix(*.status))]
    Status { url: String, status: u16 },
    /// The connection failed (refused, reset, timed out, DNS) on every attempt.
    #[error("GET {url}: {message} (gave up after {attempts} attempt{})", if *.attempts == 1 { "" } else { "s" })]
    Transport { url: String, message: String, attempts: u32 },
    /// The server's answer contradicts the checksum table or HTTP (size, Content-Range).
    #[error("GET {url}: {problem}")]
    Protocol { url: String, problem: String },
    /// The complete download does not have the digest of the checksum table; its part file was
    /// deleted.
    #[error("{material}: checksum mismatch: SHA-256 of the download is {actual}, expected {expected}; deleted {part}")]
    Checksum { material: String, part: PathBuf, expected: String, actual: String },
    /// A file already under the final name has other content; it was left untouched.
    #[error(
        "{material}: {path} already exists but {detail}; left untouched: delete it, or use --force to move it aside"
    )]
    Existing { material: String, path: PathBuf, detail: String },
    /// A local file operation failed.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl FetchError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }
}

/// " (Not Found)" and the like for the common statuses.
fn reason_suffix(status: u16) -> String {
    let reason = match status {
        400 => "Bad Request",
        401 => "Unauthorized",
        403 => "Forbidden",
        404 => "Not Found",
        408 => "Request Timeout",
        410 => "Gone",
        416 => "Range Not Satisfiable",
        429 => "Too Many Requests",
        500 => "Internal Server Error",
        502 => "Bad Gateway",
        503 => "Service Unavailable",
        504 => "Gateway Timeout",
        _ => return String::new(),
    };
    format!(" ({reason})")
}

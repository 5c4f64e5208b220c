//! The HTTP side of a download: a response's headers as text, a `Content-Range` checked
//! against the checksum table's size, and which failures are worth another attempt.
use super::error::FetchError;

/// The outcome of one attempt at the body of a download.
pub(super) enum AttemptError {
    /// Worth retrying: the next attempt resumes from the part file.
    Transient(String),
    /// Retrying cannot help.
    Fatal(FetchError),
}

/// A response header as text ("" when absent or not text).
pub(super) fn header(response: &ureq::http::Response<ureq::Body>, name: &str) -> String {
    response.headers().get(name).and_then(|v| v.to_str().ok()).unwrap_or("").to_string()
}

/// Sorts a ureq error into transient (connection-level) or fatal.
pub(super) fn classify(url: &str, error: ureq::Error) -> AttemptError {
    match error {
        ureq::Error::Io(_)
        | ureq::Error::Timeout(_)
        | ureq::Error::HostNotFound
        | ureq::Error::ConnectionFailed
        | ureq::Error::Protocol(_) => AttemptError::Transient(error.to_string()),
        other => AttemptError::Fatal(FetchError::Protocol {
            url: url.to_string(),
            problem: other.to_string(),
        }),
    }
}

/// The first byte of `Content-Range: bytes START-END/TOTAL`, checking END and TOTAL against the
/// expected size.
pub(super) fn parse_content_range(value: &str, size: u64) -> Result<u64, String> {
    let bad = || format!("malformed Content-Range {value:?}");
    let rest = value.strip_prefix("bytes ").ok_or_else(bad)?;
    let (range, total) = rest.split_once('/').ok_or_else(bad)?;
    let (start, end) = range.split_once('-').ok_or_else(bad)?;
    let start: u64 = start.trim().parse().map_err(|_| bad())?;
    let end: u64 = end.trim().parse().map_err(|_| bad())?;
    if total != "*" {
        let total: u64 = total.trim().parse().map_err(|_| bad())?;
        if total != size {
            return Err(format!("the server's file has {total} bytes (Content-Range {value:?}), the checksum table says {size}"));
        }
    }
    if start > end || end >= size {
        return Err(format!("Content-Range {value:?} lies outside a file of {size} bytes"));
    }
    Ok(start)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_range_is_checked_against_the_table() {
        assert_eq!(parse_content_range("bytes 100-199/200", 200), Ok(100));
        assert_eq!(parse_content_range("bytes 0-199/*", 200), Ok(0));
        assert!(parse_content_range("bytes 100-199/300", 200)
            .unwrap_err()
            .contains("has 300 bytes"));
        assert!(parse_content_range("bytes 100-250/200", 200).is_err());
        assert!(parse_content_range("items 1-2/3", 3).unwrap_err().contains("malformed"));
        assert!(parse_content_range("", 3).is_err());
    }
}

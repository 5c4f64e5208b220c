//! Download of the official MERL BRDF database (Matusik et al. 2003; the 100 measured materials
//! of §3.1 of the paper) for users with internet access: a bundled SHA-256 table
//! ([`checksums`]) and a resumable, verifying downloader ([`downloader`]).
pub mod checksums;
pub mod downloader;
pub mod error;
mod http;

pub use checksums::{ChecksumEntry, ChecksumTable};
pub use downloader::{
    FetchFailure, FetchOptions, FetchReport, Fetcher, MERL_BASE_URL, MERL_LEGACY_BASE_URL,
    MISMATCH_SUFFIX, PART_SUFFIX,
};
pub use error::FetchError;

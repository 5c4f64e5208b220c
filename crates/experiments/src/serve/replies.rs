//! What the editor answers the HTTP handlers: an opened material, a preview, a file to
//! download, the model it edits with, and why a job has no result ([`Failure`]).
use super::request::{AttributesJson, Quality, Refusal};
use serde::Serialize;

/// Why a job has no result.
#[derive(Debug)]
pub enum Failure {
    /// The request is wrong (4xx).
    Refused(Refusal),
    /// A newer preview replaced this one.
    Superseded,
    /// Something failed in the server (500).
    Internal(String),
}

impl From<Refusal> for Failure {
    fn from(r: Refusal) -> Self {
        Self::Refused(r)
    }
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Self::Internal(format!("{e:#}"))
    }
}

impl From<deepbrdf_eval::EvalError> for Failure {
    fn from(e: deepbrdf_eval::EvalError) -> Self {
        anyhow::Error::from(e).into()
    }
}

/// A failure inside the server, from any error.
pub(super) fn internal(e: impl std::fmt::Display) -> Failure {
    Failure::Internal(e.to_string())
}

/// An opened material, as the page sees it.
#[derive(Debug, Clone, Serialize)]
pub struct MaterialInfo {
    pub id: String,
    pub name: String,
    /// The attributes fitted to its table (the library's fit).
    pub attributes: AttributesJson,
    /// Its latent (eq. 2).
    pub latent: Vec<f32>,
}

/// A rendered preview of an edit.
#[derive(Debug, Clone, Serialize)]
pub struct Preview {
    #[serde(skip)]
    pub png: Vec<u8>,
    pub quality: Quality,
    pub size: u32,
    pub spp: u32,
    /// The latent of the edit (decoded to the previewed table); none for the modes that edit
    /// the table itself.
    pub latent: Option<Vec<f32>>,
    /// The attributes asked for.
    pub requested: AttributesJson,
    /// The attributes of the unedited (blended) material the edit starts from.
    pub base: AttributesJson,
    /// Re-estimated on the decoded table (refined previews only; the quick fit).
    pub achieved: Option<AttributesJson>,
    /// Seconds in the editor: regressor, decode (0 when cached), render, all.
    pub seconds: Seconds,
}

/// Seconds in the editor: regressor, decode or table edit (0 when cached), render, all.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Seconds {
    pub regressor: f64,
    pub decode: f64,
    pub render: f64,
    pub total: f64,
}

/// What to download.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Download {
    /// The edited MERL `.binary` table.
    Binary,
    /// The edited table as an RGL `.bsdf` file (`deepbrdf_data::rgl::export`, default
    /// resolutions), for Mitsuba 3 and pbrt-v4.
    Bsdf,
    /// The edited latent as a latent file (JSON).
    Latent,
}

/// A file to send: its name and bytes.
pub struct DownloadFile {
    pub file_name: String,
    pub bytes: Vec<u8>,
}

/// The model the server edits with.
#[derive(Debug, Clone, Serialize)]
pub struct ModelInfo {
    pub model_id: String,
    pub k: usize,
    pub model_dir: String,
}

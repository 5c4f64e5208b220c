//! The JSON file of a latent vector: the k values and the id of the model that made them.
use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `{"model_id": "...", "material": "...", "k": 10, "latent": [...]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LatentFile {
    pub model_id: String,
    pub material: String,
    pub k: usize,
    pub latent: Vec<f32>,
}

impl LatentFile {
    pub fn new(model_id: &str, material: &str, latent: Vec<f32>) -> Self {
        Self { model_id: model_id.into(), material: material.into(), k: latent.len(), latent }
    }

    /// Writes the file atomically ([`deepbrdf_data::files::write_atomic`]).
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        let text = serde_json::to_string_pretty(self)?;
        deepbrdf_data::files::write_atomic(path, (text + "\n").as_bytes())?;
        Ok(())
    }

    /// Reads and checks a latent file (at most 1 MB; k must match the values; all finite).
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let meta =
            std::fs::metadata(path).with_context(|| format!("reading {}", path.display()))?;
        if meta.len() > 1 << 20 {
            bail!("{}: {} bytes is too large for a latent vector", path.display(), meta.len());
        }
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let file: Self = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a latent vector file", path.display()))?;
        if file.k != file.latent.len() || file.k == 0 {
            bail!("{}: k = {} but {} values", path.display(), file.k, file.latent.len());
        }
        if file.latent.iter().any(|v| !v.is_finite()) {
            bail!("{}: the latent vector has a non-finite value", path.display());
        }
        Ok(file)
    }
}

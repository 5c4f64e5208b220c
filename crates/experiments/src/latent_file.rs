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
        deepbrdf_data::files::write_atomic(path, &self.to_bytes()?)?;
        Ok(())
    }

    /// The file's content, as [`save`](Self::save) writes it (for a download, say).
    pub fn to_bytes(&self) -> anyhow::Result<Vec<u8>> {
        Ok((serde_json::to_string_pretty(self)? + "\n").into_bytes())
    }

    /// Reads and checks a latent file (at most 1 MB; k must match the values; all finite).
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let meta =
            std::fs::metadata(path).with_context(|| format!("reading {}", path.display()))?;
        if meta.len() > 1 << 20 {
            bail!("{}: {} bytes is too large for a latent vector", path.display(), meta.len());
        }
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        Self::parse(path, &bytes)
    }

    /// A latent file's content `bytes` (read from `path`, named in errors), checked.
    pub fn parse(path: &Path, bytes: &[u8]) -> anyhow::Result<Self> {
        let file: Self = serde_json::from_slice(bytes)
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

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::testing::mutate::{fuzz, inputs, Focus};

    /// Mutants of real latent files are refused with an error or read, never a panic; what is
    /// read has k values, all finite. `DEEPBRDF_FUZZ_INPUTS=1000000 cargo test --release -p
    /// experiments mutated_latent -- --nocapture` runs a million.
    #[test]
    fn mutated_latent_files_are_refused_or_read_never_a_panic() {
        let corpus: Vec<Vec<u8>> = [
            LatentFile::new("3782200a62261f0ac8bfa8b16c3a1f87", "chrome", vec![0.5, -1.25, 3e-3]),
            LatentFile::new("00", "merl/gold-metallic-paint", (0..10).map(|i| i as f32).collect()),
        ]
        .iter()
        .map(|f| serde_json::to_vec_pretty(f).expect("json"))
        .collect();
        let origin = Path::new("latent.json");
        let focus = Focus { header: 512, header_share: 1.0 };
        let mut bad = 0;
        let report = fuzz(&corpus, 41, inputs(3_000), focus, |b| {
            LatentFile::parse(origin, b).map(|f| {
                bad += usize::from(f.k != f.latent.len() || f.latent.iter().any(|v| !v.is_finite()))
            })
        });
        eprintln!("latent files: {report:?}");
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert!(report.rejected > 0 && report.accepted > 0, "{report:?}");
        assert_eq!(bad, 0, "a latent file with a wrong k or a non-finite value was read");
    }
}

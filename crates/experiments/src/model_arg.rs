//! The `--model DIR` option of the commands that use a trained DeepBRDF model (`edit`,
//! `interpolate`, `recover`, ...): a model's artifact directory (or the training directory
//! holding `model/`), the shipped default model when not given.
use anyhow::bail;
use std::path::{Path, PathBuf};

/// The shipped default model, `models/default/` at the repository root: the autoencoder
/// artifact as `experiments train` saves it, with the networks trained for it beside it
/// (`regressor/` for editing, `recovery/` for single-image recovery).
pub const DEFAULT_MODEL_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/default");

#[derive(Debug, Clone, clap::Args)]
pub struct ModelArg {
    /// A trained DeepBRDF model (artifact directory, or a training directory holding `model/`);
    /// default: the model shipped in the repository (`models/default`).
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
}

impl ModelArg {
    /// The model directory to load: the one given, else the shipped default.
    pub fn dir(&self) -> anyhow::Result<PathBuf> {
        match &self.model {
            Some(dir) => {
                if !dir.exists() {
                    bail!("model directory {} does not exist", dir.display());
                }
                Ok(dir.clone())
            }
            None => {
                let dir = Path::new(DEFAULT_MODEL_DIR);
                if !dir.join("model.json").exists() && !dir.join("model").exists() {
                    bail!(
                        "no --model given and the shipped default model is not at {}: train one \
                         with `experiments train --out DIR` and pass --model DIR",
                        dir.display()
                    );
                }
                Ok(dir.to_path_buf())
            }
        }
    }
}

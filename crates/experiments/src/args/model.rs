//! The `--model DIR` option of the commands that use a trained DeepBRDF model (`encode`,
//! `decode`, `reconstruct`, `edit`, `interpolate`, `recover`, ...): a model's artifact directory
//! (or the training directory holding `model/`), the shipped default model when not given.
//! `encode`, `decode` and `reconstruct` also keep their earlier form with the model as first
//! positional argument ([`ModelArg::with_positional`]).
use anyhow::bail;
use std::path::{Path, PathBuf};

pub use deepbrdf_model::DEFAULT_MODEL_DIR;

#[derive(Debug, Clone, clap::Args)]
pub struct ModelArg {
    /// A trained DeepBRDF model (artifact directory, or a training directory holding `model/`);
    /// default: the model shipped in the repository (`models/default`).
    #[arg(long, value_name = "DIR")]
    pub model: Option<PathBuf>,
}

/// `[MODEL] MATERIAL` of `encode` and `reconstruct`: the material, and before it, optionally,
/// the model (the earlier form of `--model DIR`).
#[derive(Debug, Clone, clap::Args)]
pub struct ModelMaterialArg {
    /// [MODEL] MATERIAL: a MERL .binary file or the name of a bundled material; before it, optionally, a trained
    /// model (the earlier form of `--model DIR`).
    #[arg(value_name = "[MODEL] MATERIAL", num_args = 1..=2, required = true)]
    pub inputs: Vec<String>,
    #[command(flatten)]
    pub model: ModelArg,
}

impl ModelMaterialArg {
    /// The model directory and the material ([`ModelArg::with_positional`]).
    pub fn resolve(&self) -> anyhow::Result<(PathBuf, String)> {
        self.model.with_positional(&self.inputs)
    }
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

    /// The model and the input of a command written `[MODEL] INPUT`: with two positionals the
    /// first is the model (the earlier form; then `--model` must not be given too), with one
    /// the model is [`dir`](Self::dir).
    pub fn with_positional(&self, positionals: &[String]) -> anyhow::Result<(PathBuf, String)> {
        match positionals {
            [input] => Ok((self.dir()?, input.clone())),
            [model, input] => {
                if self.model.is_some() {
                    bail!("give the model once: as --model DIR or as the first argument");
                }
                let dir = PathBuf::from(model);
                if !dir.exists() {
                    bail!("model directory {} does not exist", dir.display());
                }
                Ok((dir, input.clone()))
            }
            _ => bail!("expected [MODEL] INPUT, got {} arguments", positionals.len()),
        }
    }
}

/// `path` as written in a results file: under the shipped model's folder, relative to the
/// repository (`models/default/...`) instead of this machine's absolute path; others as given.
pub fn shown(path: &Path) -> String {
    match path.strip_prefix(DEFAULT_MODEL_DIR) {
        Ok(rest) => Path::new("models/default").join(rest).display().to_string(),
        Err(_) => path.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_shipped_folder_is_shown_relative_to_the_repository() {
        let regressor = std::path::Path::new(super::DEFAULT_MODEL_DIR).join("regressor");
        assert_eq!(super::shown(&regressor), "models/default/regressor");
        assert_eq!(super::shown(std::path::Path::new("runs/m")), "runs/m");
    }
}

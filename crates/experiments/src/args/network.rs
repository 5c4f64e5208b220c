//! `--network DIR`: the recovery CNN (§5.2) of a model, for `recover`, `figures-recovery` and
//! `bench recover`.
use anyhow::Context;
use deepbrdf_model::recovery::artifact::RECOVERY_DIR;
use deepbrdf_model::recovery::RecoveryArtifact;
use deepbrdf_model::DeepBrdf;
use std::path::{Path, PathBuf};

/// `--network DIR`: the recovery network of a model.
#[derive(Debug, Clone, clap::Args)]
pub struct NetworkArg {
    /// The recovery network [default: MODEL/recovery, where `train-recovery --out MODEL` and
    /// the shipped model place it].
    #[arg(long, value_name = "DIR")]
    pub network: Option<PathBuf>,
}

impl NetworkArg {
    /// The network of the model in `model_dir`, loaded and checked to predict `model`'s latent.
    pub fn load(&self, model_dir: &Path, model: &DeepBrdf) -> anyhow::Result<RecoveryArtifact> {
        let dir = match &self.network {
            Some(n) => n.clone(),
            None => model_dir.join(RECOVERY_DIR),
        };
        let network = RecoveryArtifact::load(&dir)
            .with_context(|| format!("loading the recovery network {}", dir.display()))?;
        network.check_model(model.id())?;
        Ok(network)
    }
}

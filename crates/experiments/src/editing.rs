//! The edits and interpolations of §5.1 (Hu et al. 2020) on a representation with a regressor
//! (eq. (7)): a DeepBRDF model or an IPCA basis ([`Codec`]) and the regressor trained for it.
//! One home for what `edit`, `interpolate`, `figures-editing` and `bench edit` share: the
//! paper's edit `Y' = Phi(alpha')`, the residual edit `Y' = Y + Phi(alpha') - Phi(alpha)`, the
//! latent blend, and where a model's regressors live.
use crate::model_arg::ModelArg;
use anyhow::{bail, Context};
use deepbrdf_data::MerlTable;
use deepbrdf_eval::attributes::{self, Attributes, FitConfig};
use deepbrdf_eval::baseline::BaselineBasis;
use deepbrdf_eval::editing::Edit;
use deepbrdf_eval::harness::Codec;
use deepbrdf_model::burn::tensor::Device;
use deepbrdf_model::regressor::{Regressor, TargetKind};
use deepbrdf_model::DeepBrdf;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The options naming what the editing commands (`edit`, `figures-editing`, `serve`, `bench
/// edit`, `bench serve`) edit with: the model (`--model DIR`) and its regressor.
#[derive(Debug, Clone, clap::Args)]
pub struct EditorArg {
    #[command(flatten)]
    pub model: ModelArg,
    /// The regressor folder [default: <model>/regressor].
    #[arg(long, value_name = "DIR")]
    pub regressor: Option<PathBuf>,
}

/// Name of the folder holding a model's regressors, inside the model directory.
pub const REGRESSOR_DIR: &str = "regressor";

/// Which edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EditMode {
    /// The paper's edit: the latent of the edited attributes, `Y' = Phi(alpha')`.
    Paper,
    /// Keeps what the attributes do not explain: `Y' = Y + Phi(alpha') - Phi(alpha)`.
    Residual,
}

impl EditMode {
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Residual => "residual",
        }
    }
}

/// The default `--mode`: the residual edit. In the `figures-editing` suite (README, "Editing")
/// the two are close on the edits themselves (each ahead on some rows), and the residual edit
/// keeps an unedited material as it is (identity image RelAE 0.001 against 0.053).
pub const DEFAULT_MODE: EditMode = EditMode::Residual;

/// A DeepBRDF model as a [`Codec`] (eq. (2) to encode, eq. (3) to decode).
pub struct ModelCodec<'a>(pub &'a DeepBrdf);

impl Codec for ModelCodec<'_> {
    fn name(&self) -> String {
        format!("DeepBRDF-{}", self.0.k())
    }

    fn k(&self) -> usize {
        self.0.k()
    }

    fn encode(&self, table: &MerlTable) -> deepbrdf_eval::Result<Vec<f32>> {
        self.0.encode(table).map_err(|e| deepbrdf_eval::EvalError::method(self.name(), e))
    }

    fn decode(&self, code: &[f32]) -> deepbrdf_eval::Result<MerlTable> {
        self.0.decode(code).map_err(|e| deepbrdf_eval::EvalError::method(self.name(), e))
    }
}

/// A representation and its regressor.
pub struct Space<'a> {
    pub codec: &'a dyn Codec,
    pub regressor: &'a Regressor,
}

/// An edit's result.
pub struct Edited {
    /// The attributes asked for.
    pub requested: Attributes,
    pub table: MerlTable,
}

impl Space<'_> {
    /// Eq. (7): the latent of `a`.
    pub fn latent_of(&self, a: &Attributes) -> anyhow::Result<Vec<f32>> {
        Ok(self.regressor.predict(&a.to_array())?)
    }

    /// Edits `table`, whose attributes are `original` (and latent `latent`, for the residual
    /// edit), by `edit` in `mode`.
    pub fn edit(
        &self,
        latent: &[f32],
        original: &Attributes,
        edit: &Edit,
        mode: EditMode,
    ) -> anyhow::Result<Edited> {
        let requested = edit.apply(original)?;
        let latent = self.edited_latent(latent, original, &requested, mode)?;
        let table = self.codec.decode(&latent)?;
        Ok(Edited { requested, table })
    }

    /// The latent of the edit from `original` (latent `latent`, used by the residual edit) to
    /// the attributes `requested` (checked by [`Edit::apply`]), before decoding.
    pub fn edited_latent(
        &self,
        latent: &[f32],
        original: &Attributes,
        requested: &Attributes,
        mode: EditMode,
    ) -> anyhow::Result<Vec<f32>> {
        let target = self.latent_of(requested)?;
        Ok(match mode {
            EditMode::Paper => target,
            EditMode::Residual => {
                let base = self.latent_of(original)?;
                latent.iter().zip(target.iter().zip(&base)).map(|(y, (t, b))| y + t - b).collect()
            }
        })
    }
}

/// `(1 - t) a + t b`.
pub fn blend(a: &[f32], b: &[f32], t: f64) -> Vec<f32> {
    a.iter().zip(b).map(|(&x, &y)| ((1.0 - t) * f64::from(x) + t * f64::from(y)) as f32).collect()
}

/// The plain linear blend of two tables (the reference path of `interpolate`): valid cells of
/// both blended, the others invalid.
pub fn blend_tables(a: &MerlTable, b: &MerlTable, t: f64) -> anyhow::Result<MerlTable> {
    let values: Vec<f32> = a
        .values()
        .iter()
        .zip(b.values())
        .map(|(&x, &y)| match x < 0.0 || y < 0.0 {
            true => deepbrdf_data::merl::INVALID_VALUE,
            false => ((1.0 - t) * f64::from(x) + t * f64::from(y)) as f32,
        })
        .collect();
    Ok(MerlTable::from_values(values)?)
}

/// The fit used to re-estimate the attributes of decoded tables in the measures: the
/// library's, on a quarter of its cells (theta_d every 8th, phi_d every 16th; ~0.15 s).
pub fn quick_fit() -> FitConfig {
    FitConfig { theta_d_stride: 8, phi_d_stride: 16, ..FitConfig::default() }
}

/// The attributes of `table` (the library's fit).
pub fn attributes_of(
    table: &MerlTable,
    name: &str,
    config: &FitConfig,
) -> anyhow::Result<Attributes> {
    Ok(attributes::fit(table, config)
        .with_context(|| format!("fitting the attributes of {name}"))?
        .attributes)
}

/// The regressor directory of a model directory: `--regressor DIR` if given, else
/// `<model>/regressor/`.
pub fn regressor_dir(model_dir: &Path, given: Option<&Path>) -> PathBuf {
    given.map(Path::to_path_buf).unwrap_or_else(|| model_dir.join(REGRESSOR_DIR))
}

/// Loads the model of `model_dir` and its DeepBRDF regressor (refused when it belongs to
/// another model).
pub fn load_editor(
    model_dir: &Path,
    regressor: Option<&Path>,
    device: &Device,
) -> anyhow::Result<(DeepBrdf, Regressor)> {
    let model = DeepBrdf::load(model_dir, device)
        .with_context(|| format!("loading the model {}", model_dir.display()))?;
    let dir = regressor_dir(model_dir, regressor);
    if !dir.exists() {
        bail!(
            "model {} has no regressor at {} (train one with `experiments train-regressor \
             --model {}`)",
            model_dir.display(),
            dir.display(),
            model_dir.display()
        );
    }
    let regressor = Regressor::load_for(&dir, TargetKind::DeepBrdf, model.id(), model.k(), device)?;
    Ok((model, regressor))
}

/// The digest naming an IPCA basis used at `k` components (a regressor of IPCA coefficients names it).
pub fn ipca_owner_id(basis: &BaselineBasis, k: usize) -> String {
    let mut h = Sha256::new();
    h.update(basis.name().as_bytes());
    h.update((k as u64).to_le_bytes());
    basis.basis().mean().iter().for_each(|v| h.update(v.to_le_bytes()));
    h.update((basis.basis().k() as u64).to_le_bytes());
    basis.basis().components().iter().for_each(|v| h.update(v.to_le_bytes()));
    hex::encode(&h.finalize()[..16])
}

//! What the editing commands (`edit`, `interpolate`, `figures-editing`, `serve`, `bench edit`)
//! and `train-regressor` share on the command line: the model and regressor options, where a
//! model's regressors live, how they load and how one is trained and saved. The edits themselves (§5.1, eq. (7)) are the library's
//! ([`deepbrdf_eval::editing::space`]), re-exported here.
use crate::args::model::ModelArg;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::Dataset;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::attributes::{self, Attributes, FitConfig};
use deepbrdf_eval::baseline::{BaselineBasis, BaselineCodec, MappingKind};
pub use deepbrdf_eval::editing::{
    blend, blend_tables, EditMode, ModelCodec, Space, DEFAULT_LATENT_MODE, DEFAULT_MODE,
};
use deepbrdf_eval::harness::Codec as _;
use deepbrdf_model::burn::tensor::Device;
use deepbrdf_model::regressor::{
    train_regressor, Regressor, RegressorConfig, RegressorData, Target, TargetKind,
};
use deepbrdf_model::train::Session;
use deepbrdf_model::DeepBrdf;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::Arc;

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

pub use deepbrdf_model::shipped::REGRESSOR_DIR;

/// The `--mode` option's parser for `modes` ([`EditMode::ALL`], or [`EditMode::LATENT`] where the
/// edit has to be a latent).
pub fn mode_parser(
    modes: &'static [EditMode],
) -> impl clap::builder::TypedValueParser<Value = EditMode> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(modes.iter().map(|m| m.name()))
        .map(|s| s.parse().expect("a listed edit mode parses"))
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

/// The attributes of every material of `set` (the library's fit), with progress.
pub fn attributes_of_all(
    set: &Dataset,
    config: &FitConfig,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<Attributes>> {
    progress.start(set.len() as u64, "attributes");
    let attrs = set
        .names
        .iter()
        .zip(&set.tables)
        .map(|(name, t)| {
            let a = attributes_of(t, name, config);
            progress.advance(1);
            a
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    progress.finish();
    Ok(attrs)
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

/// File name of the IPCA basis trained beside an IPCA regressor.
pub const IPCA_BASIS_FILE: &str = "ipca.basis";

/// The regressor's settings for `train-regressor`'s `--epochs` and `--seed`.
pub fn config(epochs: Option<usize>, seed: u64) -> RegressorConfig {
    let mut c = RegressorConfig::default();
    if let Some(e) = epochs {
        c.training = c.training.with_epochs(e);
    }
    c.training = c.training.with_seed(seed);
    c
}

/// Trains one regressor in `out` (its run folder `out/runs/<kind>`, resumable) and saves it.
pub fn train_into(
    out: &Path,
    data: &RegressorData,
    config: &RegressorConfig,
    target: Target,
    progress: &dyn Progress,
    device: &Device,
) -> anyhow::Result<Regressor> {
    let kind = target.kind;
    let name = match kind {
        TargetKind::DeepBrdf => "deepbrdf",
        TargetKind::Ipca => "ipca",
    };
    let run_dir = out.join("runs").join(name);
    let session = Session::new(&run_dir, true, progress, &format!("regressor ({name})"));
    let regressor = train_regressor(data, config, target, &session, device)
        .with_context(|| format!("training the {name} regressor in {}", run_dir.display()))?;
    let path = out.join(kind.file_name());
    regressor.save(&path)?;
    println!(
        "{kind} regressor: {} materials, {} epochs in {:.1} s, training relative error \
         ||Y^-Y||/||Y|| {:.4} (in-sample) -> {}",
        data.names.len(),
        regressor.provenance().epochs,
        regressor.provenance().train_seconds,
        regressor.provenance().train_relative_error,
        path.display()
    );
    Ok(regressor)
}

/// IPCA at `k` over `set` (attributes `attrs`) with its regressor, for editing through IPCA
/// coefficients: the basis and regressor `train-regressor --ipca` saved in `reg_dir`, else a
/// basis fitted and a regressor trained here on `set` (its files written to `scratch`).
#[allow(clippy::too_many_arguments)]
pub fn ipca_editor(
    reg_dir: &Path,
    set: &Dataset,
    attrs: &[Attributes],
    k: usize,
    epochs: Option<usize>,
    scratch: &Path,
    progress: &dyn Progress,
    device: &Device,
) -> anyhow::Result<(BaselineCodec, Regressor)> {
    let saved_basis = reg_dir.join(IPCA_BASIS_FILE);
    let basis = Arc::new(match saved_basis.exists() {
        true => BaselineBasis::load(&saved_basis)?,
        false => {
            let refs: Vec<_> = set.tables.iter().collect();
            BaselineBasis::fit("IPCA", MappingKind::LogRelative, &refs, k, progress)?
        }
    });
    let ipca = basis.codec(k)?;
    let owner = ipca_owner_id(&basis, k);
    let regressor = match Regressor::load_for(reg_dir, TargetKind::Ipca, &owner, k, device) {
        Ok(r) => r,
        Err(_) => {
            let targets = set
                .tables
                .iter()
                .map(|t| ipca.encode(t))
                .collect::<deepbrdf_eval::Result<Vec<_>>>()?;
            let data = RegressorData {
                label: set.label.clone(),
                names: set.names.clone(),
                attributes: attrs.iter().map(Attributes::to_array).collect(),
                targets,
            };
            let config = config(epochs, 0);
            let target = Target { kind: TargetKind::Ipca, owner_id: owner, k };
            train_into(scratch, &data, &config, target, progress, device)?
        }
    };
    Ok((ipca, regressor))
}

impl EditorArg {
    /// The model directory, and the model with its DeepBRDF regressor ([`load_editor`]).
    pub fn load(&self, device: &Device) -> anyhow::Result<(PathBuf, DeepBrdf, Regressor)> {
        let model_dir = self.model.dir()?;
        let (model, regressor) = load_editor(&model_dir, self.regressor.as_deref(), device)?;
        Ok((model_dir, model, regressor))
    }
}

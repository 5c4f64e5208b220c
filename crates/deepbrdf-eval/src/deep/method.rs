//! DeepBRDF (Hu et al., CGF 2020, §3.2) as a harness [`Method`]: training per fold and k with
//! resume.
//!
//! Each (fold, k) is trained into its own directory `<models>/fold<F>/k<K>` with resume on: an
//! interrupted sweep continues where it stopped, and a finished model whose provenance matches
//! (same configuration, data label and materials) is loaded, not retrained.

use super::codec::DeepCodec;
use super::mapped_input::InputCache;
use super::NAME;
use crate::error::{EvalError, Result};
use crate::harness::{Codec, FoldTraining, Method};
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_model::autoencoder::artifact::MODEL_DIR;
use deepbrdf_model::burn::tensor::Device;
use deepbrdf_model::refine::Refinement;
use deepbrdf_model::train::json_close;
use deepbrdf_model::{DeepBrdf, ModelArtifact, TrainConfig, TrainingSet as MappedSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The training configuration of one k: a function of k (a preset, possibly with overrides).
pub type ConfigFor = dyn Fn(usize) -> TrainConfig + Send + Sync;

/// How a fit of one (fold, k) came about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitOrigin {
    /// A finished model was found and loaded.
    Loaded,
    /// The model was trained (from scratch or resumed from a checkpoint).
    Trained,
}

impl FitOrigin {
    /// The origin's name in reports (`training.csv`).
    pub fn name(self) -> &'static str {
        match self {
            FitOrigin::Loaded => "loaded",
            FitOrigin::Trained => "trained",
        }
    }
}

/// One fitted (fold, k): where it lives and how long it took.
#[derive(Clone, Debug)]
pub struct FitRecord {
    pub fold: usize,
    pub k: usize,
    pub dir: PathBuf,
    pub origin: FitOrigin,
    /// Wall seconds of this call (loading, or mapping + training + saving).
    pub seconds: f64,
    /// Seconds of training recorded in the model's provenance (over all resumed pieces).
    pub train_seconds: f64,
    /// Final mapped-space training MSE recorded in the provenance.
    pub final_mse: f64,
}

/// DeepBRDF as a harness [`Method`].
///
/// Each fold's models live in `fold<F>/k<K>` under the models directory, F the harness' fold
/// index ([`FoldTraining::fold`]; its folds are deterministic in the seed, so a rerun with the
/// same settings finds the same directories).
pub struct DeepMethod {
    config_for: Box<ConfigFor>,
    models_dir: PathBuf,
    label: String,
    device: Device,
    fits: Mutex<Vec<FitRecord>>,
    models: Mutex<Vec<(usize, usize, Arc<DeepBrdf>)>>,
    /// The k whose models stay in memory after their fold (all when `None`; the others are
    /// loaded again by [`model`](Self::model)), for models too large to keep one per fold and
    /// k in memory.
    retained: Option<Vec<usize>>,
    /// How its models refine their encodings ([`deepbrdf_model::refine`]).
    refinement: Refinement,
    /// Each training stops at the end of the first epoch past this; a rerun resumes it
    /// ([`deepbrdf_model::train_within`]).
    time_limit: Option<std::time::Duration>,
}

impl DeepMethod {
    /// A method training with `config_for(k)` into `models_dir`, on data labelled `label` (the
    /// label is recorded in each model's provenance).
    pub fn new(config_for: Box<ConfigFor>, models_dir: &Path, label: &str, device: Device) -> Self {
        Self {
            config_for,
            models_dir: models_dir.to_path_buf(),
            label: label.to_string(),
            device,
            fits: Mutex::new(Vec::new()),
            models: Mutex::new(Vec::new()),
            retained: None,
            refinement: Refinement::default(),
            time_limit: None,
        }
    }

    /// Stops each training at the end of the first epoch past `limit` (the model of the epochs
    /// done so far is evaluated; a rerun with the same settings resumes the training).
    pub fn training_within(mut self, limit: Option<std::time::Duration>) -> Self {
        self.time_limit = limit;
        self
    }

    /// Encodes with `refinement` ([`DeepBrdf::with_refinement`]).
    pub fn refining(mut self, refinement: Refinement) -> Self {
        self.refinement = refinement;
        self
    }

    /// Keeps only the models of these k in memory after their fold (see [`model`](Self::model)).
    pub fn retaining(mut self, ks: &[usize]) -> Self {
        self.retained = Some(ks.to_vec());
        self
    }

    /// The training directory of (fold, k).
    pub fn dir(models_dir: &Path, fold: usize, k: usize) -> PathBuf {
        models_dir.join(format!("fold{fold}")).join(format!("k{k}"))
    }

    /// The fits made so far, in order.
    pub fn fits(&self) -> Vec<FitRecord> {
        self.fits.lock().map(|f| f.clone()).unwrap_or_default()
    }

    /// The model fitted for (fold, k), once the harness has fitted it: from memory when it was
    /// retained, else loaded again from its directory.
    pub fn model(&self, fold: usize, k: usize) -> Option<Arc<DeepBrdf>> {
        let kept = self.models.lock().ok().and_then(|models| {
            models.iter().find(|(f, kk, _)| *f == fold && *kk == k).map(|(_, _, m)| m.clone())
        });
        kept.or_else(|| {
            let fitted = self.fits().iter().any(|r| r.fold == fold && r.k == k);
            let dir = Self::dir(&self.models_dir, fold, k);
            fitted
                .then(|| {
                    let model = DeepBrdf::load(&dir, &self.device).ok()?;
                    Some(Arc::new(model.with_refinement(self.refinement)))
                })
                .flatten()
        })
    }

    /// Loads or trains the model of (fold, k) on `train`.
    ///
    /// Training does what `deepbrdf_model::fit` does, but with the fold's eq. (1) reference
    /// from the harness and one mapped training set (`set`, built on first use) for all k of
    /// the fold, instead of a median and a mapping per k.
    fn fit_in(
        &self,
        fold: usize,
        train: &FoldTraining<'_>,
        k: usize,
        cache: &Arc<InputCache>,
        set: &mut Option<(MedianReference, MappedSet)>,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        let names = train.names;
        let started = std::time::Instant::now();
        let config = (self.config_for)(k);
        if config.model.latent != k {
            return Err(EvalError::Invalid(format!(
                "the training configuration for k = {k} has k = {}",
                config.model.latent
            )));
        }
        let dir = Self::dir(&self.models_dir, fold, k);
        let (model, origin) = match self.load_finished(&dir, &config, names)? {
            Some(model) => (model, FitOrigin::Loaded),
            None => {
                // The configuration's eq. (1) reference from the fold's median; the fold's
                // mapped set is rebuilt only if another k asks for another reference.
                let reference = config.model.mapping_reference(train.reference);
                if set.as_ref().is_some_and(|(r, _)| *r != reference) {
                    *set = None;
                }
                let (reference, mapped) = match set {
                    Some((reference, mapped)) => (&*reference, mapped),
                    None => {
                        let mapped = MappedSet::from_table_set(
                            &self.label,
                            names,
                            train.set,
                            train.indices,
                            &reference,
                        )
                        .map_err(|e| model_error(&dir, e))?;
                        let (r, m) = set.insert((reference, mapped));
                        (&*r, m)
                    }
                };
                let model = deepbrdf_model::train_within(
                    &config,
                    mapped,
                    &dir,
                    true,
                    self.time_limit,
                    progress,
                    &self.device,
                )
                .and_then(|trained| {
                    let artifact = ModelArtifact::from_trained(
                        trained,
                        reference.clone(),
                        &self.label,
                        names,
                        &self.device,
                    )?;
                    artifact.save(&dir.join(MODEL_DIR))?;
                    DeepBrdf::from_artifact(artifact, &self.device)
                })
                .map_err(|e| model_error(&dir, e))?;
                (model, FitOrigin::Trained)
            }
        };
        let model = model.with_refinement(self.refinement);
        let provenance = model.provenance();
        let record = FitRecord {
            fold,
            k,
            dir,
            origin,
            seconds: started.elapsed().as_secs_f64(),
            train_seconds: provenance.train_seconds,
            final_mse: provenance.final_mse,
        };
        if let Ok(mut fits) = self.fits.lock() {
            fits.push(record);
        }
        let model = Arc::new(model);
        let mut models = self.models.lock().map_err(|_| poisoned())?;
        // Codecs of one fold share the mapped input of the table being evaluated when their
        // models map with the same eq. (1) reference (they do: one fold, one training set).
        let same_reference = models
            .iter()
            .filter(|(f, kk, _)| *f == fold && *kk != k)
            .all(|(_, _, m)| m.reference().values() == model.reference().values());
        let cache = if same_reference { cache.clone() } else { Arc::default() };
        models.retain(|(f, kk, _)| (*f, *kk) != (fold, k));
        if self.retained.as_ref().is_none_or(|ks| ks.contains(&k)) {
            models.push((fold, k, model.clone()));
        }
        Ok(Box::new(DeepCodec::new(model, cache)))
    }

    /// The finished model in `dir` if there is one trained with `config` on `names` from this
    /// method's data label; `None` when there is none or it belongs to another run (then
    /// training resumes or restarts, and the trainer reports a conflicting checkpoint).
    fn load_finished(
        &self,
        dir: &Path,
        config: &TrainConfig,
        names: &[String],
    ) -> Result<Option<DeepBrdf>> {
        if !dir.join(MODEL_DIR).is_dir() {
            return Ok(None);
        }
        let model = match DeepBrdf::load(dir, &self.device) {
            Ok(model) => model,
            Err(e) => {
                // The trainer rebuilds the artifact from the checkpoint.
                eprintln!("note: not reusing the model in {}: {e}", dir.display());
                return Ok(None);
            }
        };
        let wanted = serde_json::to_value(config).map_err(|e| {
            EvalError::Invalid(format!("cannot serialise the training configuration: {e}"))
        })?;
        let p = model.provenance();
        let mismatch = if !json_close(&p.train_config, &wanted) {
            Some("it was trained with another configuration")
        } else if p.data_label != self.label || p.materials != names {
            Some("it was trained on other materials")
        } else if p.epochs != config.epochs {
            Some("it has another number of epochs")
        } else {
            None
        };
        if let Some(why) = mismatch {
            eprintln!("note: not reusing the model in {}: {why}", dir.display());
            return Ok(None);
        }
        Ok(Some(model))
    }
}

fn poisoned() -> EvalError {
    EvalError::Invalid(format!("{NAME}: a lock was poisoned by an earlier panic"))
}

fn model_error(dir: &Path, e: deepbrdf_model::ModelError) -> EvalError {
    EvalError::method(format!("{NAME} in {}", dir.display()), e)
}

impl Method for DeepMethod {
    fn name(&self) -> String {
        NAME.to_string()
    }

    /// Fits into the directory of fold 0 (a fit outside the harness' folds).
    fn fit(
        &self,
        train: &[&MerlTable],
        names: &[String],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        let reference = MedianReference::from_tables(train)?;
        let tables = train.to_vec();
        let indices: Vec<usize> = (0..tables.len()).collect();
        let set =
            FoldTraining { fold: 0, set: &tables, indices: &indices, names, reference: &reference };
        self.fit_in(set.fold, &set, k, &Arc::default(), &mut None, progress)
    }

    fn fit_fold(
        &self,
        train: &FoldTraining<'_>,
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let fold = train.fold;
        let cache = Arc::new(InputCache::default());
        let mut set = None;
        let codecs = ks
            .iter()
            .map(|&k| self.fit_in(fold, train, k, &cache, &mut set, progress))
            .collect::<Result<Vec<_>>>()?;
        Ok(codecs)
    }
}

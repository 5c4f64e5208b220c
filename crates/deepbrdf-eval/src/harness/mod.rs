//! The evaluation harness (paper §4): fits each [`Method`] on the training materials of each
//! fold of a [`Mode`], encodes and decodes every evaluation material at every k, and records
//! each [`Measure`]. PCA, IPCA and DeepBRDF all run through [`run`] unchanged.

mod at_ks;
mod codec;
mod measures;
mod modes;
mod read;
mod report;

pub use at_ks::AtKs;
pub use codec::{Codec, FoldTraining, Method};
pub use deepbrdf_data::mapping::MedianReference;
pub use measures::{Measure, Original, Yardstick};
pub use modes::{Fold, Mode};
pub(crate) use read::{csv_rows, parsed};
pub(crate) use report::csv_field;
pub use report::{FitTiming, Record, Results};

use crate::error::{EvalError, Result};
use crate::metrics::{ImageRelae, ImageRelaeConfig};
use deepbrdf_data::table_set::{Concatenated, TableSet};
use deepbrdf_data::{MerlTable, Progress};
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct HarnessConfig {
    /// Dimensions of the representation to evaluate.
    pub ks: Vec<usize>,
    pub mode: Mode,
    /// Seed of the k-fold split.
    pub seed: u64,
    pub measures: Vec<Measure>,
    /// In k-fold mode, score only this fold (its held-out materials, with a codec fitted on
    /// the others): one held-out experiment at the cost of one training.
    pub only_fold: Option<usize>,
}

impl HarnessConfig {
    /// Checks the settings once (non-empty, distinct, positive k; at least one measure).
    pub fn validate(&self) -> Result<()> {
        if self.ks.is_empty() || self.ks.contains(&0) {
            return Err(EvalError::Invalid("k values must be given and positive".into()));
        }
        let mut sorted = self.ks.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != self.ks.len() {
            return Err(EvalError::Invalid(format!("repeated k in {:?}", self.ks)));
        }
        if self.measures.is_empty() {
            return Err(EvalError::Invalid("no measure selected".into()));
        }
        let mut measures = self.measures.clone();
        measures.sort_unstable();
        measures.dedup();
        if measures.len() != self.measures.len() {
            return Err(EvalError::Invalid(format!("repeated measure in {:?}", self.measures)));
        }
        match (self.only_fold, self.mode) {
            (None, _) => {}
            (Some(f), Mode::KFold { folds }) if f >= folds => {
                return Err(EvalError::Invalid(format!(
                    "fold {f} does not exist: kfold:{folds} has folds 0 to {}",
                    folds - 1
                )))
            }
            (Some(_), Mode::KFold { .. }) => {}
            (Some(_), mode) => {
                return Err(EvalError::Invalid(format!(
                    "one fold can be chosen in kfold mode only, not in {mode} mode"
                )))
            }
        }
        Ok(())
    }
}

/// Named tables: the materials of a run (a `Dataset`'s names and tables, in memory or
/// streamed: the harness reads one at a time where it can).
#[derive(Clone, Copy)]
pub struct Materials<'a> {
    pub names: &'a [String],
    pub tables: &'a dyn TableSet,
    /// How the data came about, for the summary ("bundled merl (100)").
    pub label: &'a str,
}

impl<'a> Materials<'a> {
    fn check(&self) -> Result<()> {
        if self.names.len() != self.tables.len() {
            return Err(EvalError::Invalid(format!(
                "{} names for {} tables",
                self.names.len(),
                self.tables.len()
            )));
        }
        Ok(())
    }
}

/// Runs `methods` over `train` (and, in generalize mode, evaluates on `eval`).
///
/// In-sample and k-fold modes evaluate materials of `train` (and `eval` must be `None`);
/// generalize mode fits on all of `train` and evaluates on all of `eval`. A k-fold run never
/// evaluates a material with a codec fitted on it.
pub fn run(
    methods: &[&dyn Method],
    config: &HarnessConfig,
    train: Materials,
    eval: Option<Materials>,
    progress: &dyn Progress,
) -> Result<Results> {
    run_with_extra(methods, config, train, None, eval, progress)
}

/// [`run`], with `extra` materials in every fold's training set and never scored (e.g.
/// the other bundled collections beside a k-fold split of `merl`). The folds split `train`
/// alone, so a k-fold run still never evaluates a material with a codec fitted on it.
pub fn run_with_extra(
    methods: &[&dyn Method],
    config: &HarnessConfig,
    train: Materials,
    extra: Option<Materials>,
    eval: Option<Materials>,
    progress: &dyn Progress,
) -> Result<Results> {
    config.validate()?;
    train.check()?;
    if let Some(extra) = &extra {
        extra.check()?;
        if let Some(name) = extra.names.iter().find(|n| train.names.contains(n)) {
            return Err(EvalError::Invalid(format!(
                "{name} is both in {} and among the extra training materials ({})",
                train.label, extra.label
            )));
        }
    }
    let scored = train.tables.len();
    // The summary's training data names the extra materials; its evaluation data does not.
    let train_label = match &extra {
        Some(extra) => format!("{} + {}", train.label, extra.label),
        None => train.label.to_string(),
    };
    let all_names: Vec<String>;
    let concatenated;
    let train = match &extra {
        Some(extra) => {
            all_names = train.names.iter().chain(extra.names).cloned().collect();
            concatenated = Concatenated { first: train.tables, second: extra.tables };
            Materials { names: &all_names, tables: &concatenated, label: train.label }
        }
        None => train,
    };
    if methods.is_empty() {
        return Err(EvalError::Invalid("no method to evaluate".into()));
    }
    let eval_set = match (config.mode, eval) {
        (Mode::Generalize, Some(e)) => {
            e.check()?;
            e
        }
        (Mode::Generalize, None) => {
            return Err(EvalError::Invalid("generalize mode needs evaluation materials".into()))
        }
        (_, Some(_)) => {
            return Err(EvalError::Invalid(format!(
                "{} mode evaluates the training collection; no separate evaluation set",
                config.mode
            )))
        }
        (_, None) => train,
    };
    // Table measures first (one pass over the cells), then the rendered one.
    let table_measures: Vec<Measure> =
        config.measures.iter().copied().filter(|m| !m.renders()).collect();
    let renders = config.measures.iter().any(|m| m.renders());
    let mut measure_order = table_measures.clone();
    if renders {
        measure_order.push(Measure::ImageRelae);
    }
    let started = Instant::now();
    let mut folds = config.mode.folds(scored, eval_set.tables.len(), config.seed)?;
    if let Some(only) = config.only_fold {
        folds.retain(|f| f.index == only);
    }
    for fold in &mut folds {
        fold.train.extend(scored..train.tables.len());
    }
    let mut records = Vec::new();
    let mut fits = Vec::new();
    let mut eval_seconds = 0.0;
    for fold in &folds {
        let names: Vec<String> = fold.train.iter().map(|&i| train.names[i].clone()).collect();
        if config.mode != Mode::Generalize {
            // Guard the promise of held-out modes explicitly.
            if config.mode != Mode::InSample && fold.test.iter().any(|t| fold.train.contains(t)) {
                return Err(EvalError::Invalid(format!(
                    "fold {} evaluates a training material",
                    fold.index
                )));
            }
        }
        // The median needs every training table at once; they are let go afterwards.
        let yardstick = {
            let tables = fold.train.iter().map(|&i| train.tables.table(i)).collect::<Vec<_>>();
            let tables = tables.into_iter().collect::<deepbrdf_data::Result<Vec<_>>>()?;
            let refs: Vec<&MerlTable> = tables.iter().map(|t| &**t).collect();
            Yardstick::from_training(&refs)?
        };
        let set = FoldTraining {
            fold: fold.index,
            set: train.tables,
            indices: &fold.train,
            names: &names,
            reference: yardstick.reference(),
        };
        // Each method is fitted, evaluated and let go before the next one is fitted (only one
        // method's codecs in memory at a time); the records are gathered per material and
        // kept in the order material, method, codec, measure.
        let mut per_material: Vec<Vec<Record>> = vec![Vec::new(); fold.test.len()];
        for method in methods {
            let ks = method.ks(&config.ks);
            if let Some(k) = ks.iter().find(|k| !config.ks.contains(k)) {
                return Err(EvalError::Invalid(format!(
                    "{} asked for k = {k}, which is not among the evaluated k {:?}",
                    method.name(),
                    config.ks
                )));
            }
            if ks.is_empty() {
                continue;
            }
            let t = Instant::now();
            let codecs = method.fit_fold(&set, &ks, progress)?;
            if codecs.len() != ks.len() || codecs.iter().zip(&ks).any(|(c, &k)| c.k() != k) {
                return Err(EvalError::Invalid(format!(
                    "{} returned codecs for k = {:?}, expected {:?}",
                    method.name(),
                    codecs.iter().map(|c| c.k()).collect::<Vec<_>>(),
                    ks
                )));
            }
            fits.push(FitTiming {
                method: method.name(),
                fold: fold.index,
                n_train: fold.train.len(),
                seconds: t.elapsed().as_secs_f64(),
            });

            let t = Instant::now();
            let name = method.name();
            let steps = fold.test.len() * codecs.len();
            progress.start(steps as u64, &format!("evaluating fold {}: {name}", fold.index + 1));
            for (&i, records) in fold.test.iter().zip(per_material.iter_mut()) {
                let table = eval_set.tables.table(i)?;
                let original = yardstick.original(&table);
                let image = match renders {
                    true => Some(ImageRelae::new(&table, &ImageRelaeConfig::default())?),
                    false => None,
                };
                for codec in &codecs {
                    let code = codec.encode(&table)?;
                    if code.len() != codec.k() {
                        return Err(EvalError::Invalid(format!(
                            "{} encoded {} to {} coefficients",
                            codec.name(),
                            eval_set.names[i],
                            code.len()
                        )));
                    }
                    let recon = codec.decode(&code)?;
                    let mut values = yardstick.measure(&original, &recon, &table_measures)?;
                    if let Some(image) = &image {
                        values.push(image.measure(&recon)?);
                    }
                    for (&measure, value) in measure_order.iter().zip(values) {
                        records.push(Record {
                            method: name.clone(),
                            k: codec.k(),
                            fold: fold.index,
                            material: eval_set.names[i].clone(),
                            measure,
                            value,
                        });
                    }
                    progress.advance(1);
                }
            }
            progress.finish();
            eval_seconds += t.elapsed().as_secs_f64();
        }
        records.extend(per_material.into_iter().flatten());
    }
    Ok(Results {
        mode: config.mode,
        seed: config.seed,
        ks: config.ks.clone(),
        methods: methods.iter().map(|m| m.name()).collect(),
        measures: config.measures.clone(),
        train_label,
        eval_label: match (config.only_fold, folds.first()) {
            (Some(f), Some(fold)) => {
                format!("{}, fold {f} only ({} scored)", eval_set.label, fold.test.len())
            }
            _ => eval_set.label.to_string(),
        },
        records,
        fits,
        eval_seconds,
        total_seconds: started.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests;

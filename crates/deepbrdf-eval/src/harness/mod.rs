//! The evaluation harness (paper §4): fits each [`Method`] on the training materials of each
//! fold of a [`Mode`], encodes and decodes every evaluation material at every k, and records
//! each [`Measure`]. PCA, IPCA and DeepBRDF all run through [`run`] unchanged.

mod at_ks;
mod codec;
mod measures;
mod modes;
mod report;

pub use at_ks::AtKs;
pub use codec::{Codec, FoldTraining, Method};
pub use deepbrdf_data::mapping::MedianReference;
pub use measures::{Measure, Original, Yardstick};
pub use modes::{Fold, Mode};
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

/// [`run`], with `extra` materials in every fold's training set and never scored (issue 13:
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
        eval_label: eval_set.label.to_string(),
        records,
        fits,
        eval_seconds,
        total_seconds: started.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::BaselineMethod;
    use deepbrdf_data::testing::sparse_set;
    use deepbrdf_data::Silent;
    use std::sync::Mutex;

    fn methods() -> (BaselineMethod, BaselineMethod) {
        (crate::baseline::BaselineMethod::pca(), crate::baseline::BaselineMethod::ipca())
    }

    #[test]
    fn image_relae_is_measured_on_renders_and_vanishes_for_an_exact_reconstruction() {
        let (names, tables) = sparse_set(4);
        let (pca, _) = methods();
        let config = HarnessConfig {
            ks: vec![1, 3],
            mode: Mode::InSample,
            seed: 1,
            measures: vec![Measure::ImageRelae, Measure::MappedMse],
        };
        let data = Materials { names: &names, tables: &tables, label: "synthetic" };
        let results = run(&[&pca], &config, data, None, &Silent).unwrap();
        assert_eq!(results.records.len(), 2 * 4 * 2);
        let relae = |k: usize| results.mean("PCA", k, Measure::ImageRelae).unwrap();
        // k = n-1 reproduces the tables, so their renders agree (same seed, same directions).
        assert!(relae(1) > 1e-3, "{}", relae(1));
        assert!(relae(3) < 1e-4 * relae(1).max(1.0), "{} vs {}", relae(3), relae(1));
        // Each record carries its own measure: the mapped-space values are the table ones.
        let mapped = results.mean("PCA", 1, Measure::MappedMse).unwrap();
        assert!(mapped > 0.0 && (mapped - relae(1)).abs() > 1e-9);
        let repeated = HarnessConfig { measures: vec![Measure::MappedMse; 2], ..config };
        assert!(run(&[&pca], &repeated, data, None, &Silent).is_err());
    }

    #[test]
    fn in_sample_error_falls_with_k_and_vanishes_at_n_minus_1() {
        let (names, tables) = sparse_set(6);
        let (pca, ipca) = methods();
        let config = HarnessConfig {
            ks: vec![1, 2, 5],
            mode: Mode::InSample,
            seed: 1,
            measures: Measure::TABLE.to_vec(),
        };
        let data = Materials { names: &names, tables: &tables, label: "synthetic" };
        let results = run(&[&pca, &ipca], &config, data, None, &Silent).unwrap();
        assert_eq!(results.records.len(), 2 * 3 * 6 * 2);
        for method in ["PCA", "IPCA"] {
            for m in Measure::TABLE {
                let e: Vec<f64> =
                    [1, 2, 5].iter().map(|&k| results.mean(method, k, m).unwrap()).collect();
                assert!(e[1] <= e[0] && e[2] <= e[1], "{method} {m}: {e:?}");
                // k = n-1 reproduces the training set up to f32 round-off: tables, rows and
                // components are stored in f32 (relative resolution 2^-24 = 6e-8), so a root
                // measure (cos_rmse) is left at ~1e-7 of the data's scale and a squared one
                // (mapped_mse) at ~1e-14. IPCA's inverse divides by w = cos_i cos_o, which is
                // ~1e-4 at the grid's most grazing valid cells, amplifying that round-off by
                // ~eps / (w rho) there (measured: mapped_mse up to ~4e-10 of the k = 1 value). The
                // bounds allow 100x the round-off level, relative to k = 1.
                let bound = match m {
                    Measure::MappedMse => 1e-8,
                    Measure::CosRmse => 1e-5,
                    Measure::ImageRelae => unreachable!("not measured here"),
                };
                assert!(e[2] < bound * e[0], "{method} {m}: k = n-1 gives {e:?}");
            }
        }
        let dir = tempfile::tempdir().unwrap();
        results.write(dir.path()).unwrap();
        let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + results.records.len());
        let md = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
        assert!(md.contains("| IPCA |") && md.contains("k = 5"), "{md}");
        for f in ["error_vs_k_mapped_mse.svg", "per_material_cos_rmse.svg", "fits.csv"] {
            assert!(dir.path().join(f).is_file(), "{f} missing");
        }
    }

    #[test]
    fn a_method_restricted_to_some_k_is_fitted_and_scored_only_there() {
        let (names, tables) = sparse_set(9);
        let (pca, ipca) = methods();
        let config = HarnessConfig {
            ks: vec![1, 2, 3],
            mode: Mode::KFold { folds: 3 },
            seed: 3,
            measures: vec![Measure::MappedMse],
        };
        let data = Materials { names: &names, tables: &tables, label: "synthetic" };
        let only_2 = AtKs::new(&ipca, &[2, 7]);
        let results = run(&[&pca, &only_2], &config, data, None, &Silent).unwrap();
        assert_eq!(results.records.len(), 9 * 3 + 9);
        assert!(results.mean("IPCA", 1, Measure::MappedMse).is_none());
        assert!(results.mean("IPCA", 3, Measure::MappedMse).is_none());
        // The same numbers as an unrestricted run at that k.
        let full = run(&[&ipca], &config, data, None, &Silent).unwrap();
        assert_eq!(
            results.mean("IPCA", 2, Measure::MappedMse),
            full.mean("IPCA", 2, Measure::MappedMse)
        );
        assert!(results.summary_table().contains(" - |"));
        let dir = tempfile::tempdir().unwrap();
        results.write(dir.path()).unwrap();
        // Restricted to no evaluated k at all: the method has no record.
        let none = AtKs::new(&ipca, &[9]);
        let results = run(&[&pca, &none], &config, data, None, &Silent).unwrap();
        assert!(results.records.iter().all(|r| r.method == "PCA"));
    }

    /// A method whose codecs refuse to encode any table they were fitted on, and which records
    /// the training sets it saw.
    struct Spy {
        fitted: Mutex<Vec<Vec<String>>>,
    }

    struct SpyCodec {
        train: Vec<MerlTable>,
        k: usize,
    }

    impl Codec for SpyCodec {
        fn name(&self) -> String {
            "spy".into()
        }
        fn k(&self) -> usize {
            self.k
        }
        fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
            if self.train.iter().any(|t| t == table) {
                return Err(EvalError::Invalid("evaluated a training material".into()));
            }
            Ok(vec![0.0; self.k])
        }
        fn decode(&self, _code: &[f32]) -> Result<MerlTable> {
            Ok(self.train[0].clone())
        }
    }

    impl Method for Spy {
        fn name(&self) -> String {
            "spy".into()
        }
        fn fit(
            &self,
            train: &[&MerlTable],
            names: &[String],
            k: usize,
            _p: &dyn Progress,
        ) -> Result<Box<dyn Codec>> {
            self.fitted.lock().unwrap().push(names.to_vec());
            Ok(Box::new(SpyCodec { train: train.iter().map(|t| (*t).clone()).collect(), k }))
        }
    }

    /// 3-fold mode at k = 2, mapped MSE only.
    fn kfold3() -> HarnessConfig {
        HarnessConfig {
            ks: vec![2],
            mode: Mode::KFold { folds: 3 },
            seed: 5,
            measures: vec![Measure::MappedMse],
        }
    }

    #[test]
    fn kfold_never_evaluates_a_material_it_was_fitted_on() {
        let (names, tables) = sparse_set(7);
        let spy = Spy { fitted: Mutex::new(Vec::new()) };
        let config = kfold3();
        let data = Materials { names: &names, tables: &tables, label: "synthetic" };
        let results = run(&[&spy], &config, data, None, &Silent).unwrap();
        // Every material evaluated exactly once, by a fold that did not train on it.
        let mut evaluated: Vec<&str> =
            results.records.iter().map(|r| r.material.as_str()).collect();
        evaluated.sort_unstable();
        let mut all: Vec<&str> = names.iter().map(|s| s.as_str()).collect();
        all.sort_unstable();
        assert_eq!(evaluated, all);
        {
            // (The guard must be gone before `run` calls `Spy::fit` again below.)
            let fitted = spy.fitted.lock().unwrap();
            assert_eq!(fitted.len(), 3);
            for r in &results.records {
                assert!(!fitted[r.fold].contains(&r.material), "{} in fold {}", r.material, r.fold);
            }
        }
        // The same spy fails in-sample mode, which is the point of the check.
        let in_sample = HarnessConfig { mode: Mode::InSample, ..config };
        assert!(run(&[&spy], &in_sample, data, None, &Silent).is_err());
    }

    #[test]
    fn extra_materials_train_every_fold_and_are_never_scored() {
        let (names, tables) = sparse_set(9);
        let spy = Spy { fitted: Mutex::new(Vec::new()) };
        let config = kfold3();
        let (scored, others) = (tables[..6].to_vec(), tables[6..].to_vec());
        let data = Materials { names: &names[..6], tables: &scored, label: "scored" };
        let extra = Materials { names: &names[6..], tables: &others, label: "extra" };
        let results = run_with_extra(&[&spy], &config, data, Some(extra), None, &Silent).unwrap();
        let mut evaluated = results.materials();
        evaluated.sort_unstable();
        assert_eq!(evaluated, names[..6].to_vec());
        assert_eq!(
            (results.train_label.as_str(), results.eval_label.as_str()),
            ("scored + extra", "scored")
        );
        let fitted = spy.fitted.lock().unwrap();
        assert_eq!(fitted.len(), 3);
        for (fold, names_fitted) in fitted.iter().enumerate() {
            assert_eq!(results.fits[fold].n_train, 4 + 3);
            assert!(names[6..].iter().all(|n| names_fitted.contains(n)), "fold {fold}");
        }
        for r in &results.records {
            assert!(!fitted[r.fold].contains(&r.material), "{} in fold {}", r.material, r.fold);
        }
        drop(fitted);
        // A material in both sets is refused.
        let clash = Materials { names: &names[5..8], tables: &tables[5..8].to_vec(), label: "x" };
        let err = run_with_extra(&[&spy], &config, data, Some(clash), None, &Silent).unwrap_err();
        assert!(err.to_string().contains("sparse-5"), "{err}");
    }

    #[test]
    fn generalize_fits_on_one_set_and_evaluates_another() {
        let (names, tables) = sparse_set(7);
        let (pca, _) = methods();
        let config = HarnessConfig {
            ks: vec![2, 3],
            mode: Mode::Generalize,
            seed: 0,
            measures: vec![Measure::MappedMse],
        };
        let (first, last) = (tables[..5].to_vec(), tables[5..].to_vec());
        let train = Materials { names: &names[..5], tables: &first, label: "first five" };
        let eval = Materials { names: &names[5..], tables: &last, label: "last two" };
        let results = run(&[&pca], &config, train, Some(eval), &Silent).unwrap();
        assert_eq!(results.materials(), names[5..].to_vec());
        assert_eq!(results.fits[0].n_train, 5);
        assert!(run(&[&pca], &config, train, None, &Silent).is_err());
        let bad = HarnessConfig { ks: vec![2, 2], ..config.clone() };
        assert!(run(&[&pca], &bad, train, Some(eval), &Silent).is_err());
        let too_big = HarnessConfig { ks: vec![5], ..config };
        assert!(run(&[&pca], &too_big, train, Some(eval), &Silent).is_err());
    }
}

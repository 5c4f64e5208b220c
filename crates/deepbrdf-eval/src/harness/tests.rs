//! The harness run end to end on small synthetic sets: every mode, measure and restriction.
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
        only_fold: None,
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
        only_fold: None,
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
                other => unreachable!("{other} is not measured here"),
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
        only_fold: None,
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
        only_fold: None,
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
    let mut evaluated: Vec<&str> = results.records.iter().map(|r| r.material.as_str()).collect();
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
fn one_fold_alone_is_trained_once_and_scores_only_its_held_out_materials() {
    let (names, tables) = sparse_set(7);
    let data = Materials { names: &names, tables: &tables, label: "synthetic" };
    let all =
        run(&[&Spy { fitted: Mutex::new(Vec::new()) }], &kfold3(), data, None, &Silent).unwrap();
    let spy = Spy { fitted: Mutex::new(Vec::new()) };
    let config = HarnessConfig { only_fold: Some(1), ..kfold3() };
    let results = run(&[&spy], &config, data, None, &Silent).unwrap();
    let fold1: Vec<&str> =
        all.records.iter().filter(|r| r.fold == 1).map(|r| r.material.as_str()).collect();
    let scored: Vec<&str> = results.records.iter().map(|r| r.material.as_str()).collect();
    assert!(!fold1.is_empty());
    assert_eq!(scored, fold1);
    assert!(results.records.iter().all(|r| r.fold == 1));
    assert_eq!(spy.fitted.lock().unwrap().len(), 1);
    assert!(results.eval_label.contains("fold 1 only"), "{}", results.eval_label);
    // A fold that does not exist, and a fold outside k-fold mode, are refused.
    let missing = HarnessConfig { only_fold: Some(3), ..kfold3() };
    let err = run(&[&spy], &missing, data, None, &Silent).unwrap_err().to_string();
    assert!(err.contains("fold 3 does not exist"), "{err}");
    let in_sample = HarnessConfig { mode: Mode::InSample, only_fold: Some(0), ..kfold3() };
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
        only_fold: None,
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

//! `experiments baselines` end to end on a small folder of MERL files.
use crate::util;
use deepbrdf_data::merl::grid::theta_h_of;
use deepbrdf_data::merl::io::{read_merl, write_merl};
use deepbrdf_data::{MerlTable, Silent};
use deepbrdf_eval::baseline::BaselineMethod;
use deepbrdf_eval::harness::{self, HarnessConfig, Materials, Measure, Method, Mode};
use std::collections::BTreeMap;
use std::path::Path;

/// `results.csv` as `(method, k, material, measure) -> value`, checking its header and fields.
fn read_results(path: &Path) -> BTreeMap<(String, usize, String, String), f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("method,k,fold,material,measure,value"));
    let mut rows = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 6, "{line}");
        let key = (f[0].to_string(), f[1].parse().unwrap(), f[3].to_string(), f[4].to_string());
        assert_eq!(f[2], "0", "in-sample has one fold: {line}");
        assert!(rows.insert(key, f[5].parse::<f64>().unwrap()).is_none(), "repeated row {line}");
    }
    rows
}

/// Writes `n` MERL files (a diffuse colour plus a theta_h lobe, varied per material) into `dir`.
fn write_materials(dir: &Path, n: usize) {
    std::fs::create_dir_all(dir).unwrap();
    for i in 0..n {
        let f = i as f32;
        let table = MerlTable::from_fn(|h, _, _| {
            let th = theta_h_of(h) as f32;
            let lobe = (1.0 + f) * (-(th * th) / (0.02 + 0.03 * f)).exp();
            [0.1 + 0.05 * f, 0.3 - 0.04 * f, 0.2].map(|a| a + lobe)
        });
        write_merl(&table, dir.join(format!("material-{i}.binary"))).unwrap();
    }
}

#[test]
fn baselines_in_sample_writes_results_and_bases_and_protects_them() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 4);
    let data = data.to_str().unwrap();
    let args = ["baselines", "--data", data, "--k", "1,3", "--out", "res", "--save-basis", "bases"];
    let out = util::run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    assert!(
        text.contains("| PCA |") && text.contains("| IPCA |") && text.contains("k = 3"),
        "{text}"
    );
    // 4 materials, 3 = n - 1 components: in-sample error at round-off level (printed as e-1x).
    let ipca_row = text.lines().find(|l| l.starts_with("| IPCA |")).unwrap_or_default();
    let last: f64 =
        ipca_row.trim_end_matches('|').rsplit('|').next().unwrap().trim().parse().unwrap();
    assert!(last < 1e-8, "{ipca_row}");
    for f in [
        "results.csv",
        "summary.md",
        "fits.csv",
        "error_vs_k_mapped_mse.svg",
        "per_material_cos_rmse.svg",
    ] {
        assert!(dir.path().join("res").join(f).is_file(), "{f} missing");
    }
    for f in ["PCA.basis", "IPCA.basis"] {
        assert!(dir.path().join("bases").join(f).is_file(), "{f} missing");
    }
    // The CSV holds exactly what the library's harness computes on the same files, and the
    // error falls with k for both methods and both measures.
    let rows = read_results(&dir.path().join("res/results.csv"));
    // The default measures: the two errors and the highlight's two defects.
    assert_eq!(rows.len(), 2 * 2 * 4 * 4, "methods x k x materials x measures");
    let names: Vec<String> = (0..4).map(|i| format!("material-{i}")).collect();
    let tables: Vec<MerlTable> = names
        .iter()
        .map(|n| read_merl(Path::new(data).join(format!("{n}.binary"))).unwrap())
        .collect();
    let config = HarnessConfig {
        ks: vec![1, 3],
        mode: Mode::InSample,
        seed: 0,
        measures: [Measure::TABLE, Measure::HIGHLIGHT].concat(),
        only_fold: None,
    };
    let (pca, ipca) = (BaselineMethod::pca(), BaselineMethod::ipca());
    let methods: [&dyn Method; 2] = [&pca, &ipca];
    let label = "direct";
    let direct = harness::run(
        &methods,
        &config,
        Materials { names: &names, tables: &tables, label },
        None,
        &Silent,
    )
    .unwrap();
    assert_eq!(direct.records.len(), rows.len());
    for r in &direct.records {
        let key = (r.method.clone(), r.k, r.material.clone(), r.measure.name().to_string());
        let got = rows.get(&key).copied().unwrap_or(f64::INFINITY);
        assert!(
            got == r.value || (got.is_nan() && r.value.is_nan()),
            "{key:?}: {got} vs {}",
            r.value
        );
    }
    for method in ["PCA", "IPCA"] {
        for measure in ["mapped_mse", "cos_rmse"] {
            let mean = |k: usize| {
                names
                    .iter()
                    .map(|n| rows[&(method.into(), k, n.clone(), measure.into())])
                    .sum::<f64>()
                    / 4.0
            };
            assert!(mean(3) < 1e-3 * mean(1), "{method} {measure}: {} -> {}", mean(1), mean(3));
        }
    }
    // A second run into the same folders refuses before doing any work ...
    std::fs::write(dir.path().join("res/notes.txt"), "mine").unwrap();
    let again = util::run_in(dir.path(), &args);
    util::assert_clean_failure(&again, "--force");
    // ... and with --force replaces only its own files.
    let mut forced = args.to_vec();
    forced.push("--force");
    let out = util::run_in(dir.path(), &forced);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert_eq!(std::fs::read_to_string(dir.path().join("res/notes.txt")).unwrap(), "mine");
}

#[test]
fn baselines_rejects_bad_arguments_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 3);
    let data = data.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["--mode", "kfold:1"], "at least 2 folds"),
        (&["--mode", "sideways"], "unknown mode"),
        (&["--mode", "kfold:3", "--save-basis", "b"], "--save-basis"),
        (&["--k", "2,2"], "repeated k"),
        (&["--k", "5"], "k must be in 1..=2"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["baselines", "--data", data];
        args.extend_from_slice(extra);
        util::assert_clean_failure(&util::run_in(dir.path(), &args), needle);
    }
    let missing = util::run_in(dir.path(), &["baselines", "--data", "no-such-dir"]);
    util::assert_clean_failure(&missing, "no-such-dir");
}

#[test]
fn baselines_write_the_same_bytes_with_one_thread_and_with_several() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 5);
    let data = data.to_str().unwrap();
    let mut csv = Vec::new();
    for (threads, out) in [(1, "one"), (3, "three")] {
        let args = ["baselines", "--data", data, "--k", "1,2", "--out", out];
        let output = util::run_on_threads(dir.path(), &args, threads);
        assert!(output.status.success(), "{}", util::stderr(&output));
        csv.push(std::fs::read(dir.path().join(out).join("results.csv")).unwrap());
    }
    assert!(csv[0] == csv[1], "results.csv differs between 1 and 3 threads");
}

#[test]
fn folds_lists_the_materials_each_fold_of_baselines_scores() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 7);
    let d = data.to_str().unwrap();
    let out = util::run_in(
        dir.path(),
        &[
            "baselines",
            "--mode",
            "kfold:3",
            "--k",
            "1",
            "--methods",
            "pca",
            "--measures",
            "mapped_mse",
            "--data",
            d,
            "--out",
            "res",
        ],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    let csv = std::fs::read_to_string(dir.path().join("res").join("results.csv")).unwrap();
    let mut scored: Vec<String> =
        csv.lines().skip(1).map(|l| l.split(',').collect::<Vec<_>>()[2..4].join("\t")).collect();
    scored.sort();
    let out = util::run_in(dir.path(), &["folds", "--mode", "kfold:3", "--data", d]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let mut listed: Vec<String> = util::stdout(&out).lines().map(str::to_string).collect();
    listed.sort();
    assert_eq!(listed, scored, "every material once, in the fold baselines scored it in");
    let out = util::run_in(dir.path(), &["folds", "--mode", "kfold:3", "--fold", "1", "--data", d]);
    let fold1: Vec<String> = util::stdout(&out).lines().map(|m| format!("1\t{m}")).collect();
    assert!(!fold1.is_empty() && fold1.iter().all(|l| scored.contains(l)), "{fold1:?}");
    let out = util::run_in(dir.path(), &["folds", "--mode", "kfold:3", "--fold", "3", "--data", d]);
    util::assert_clean_failure(&out, "folds 0 to 2");
    // `baselines --fold 1` scores exactly those materials, fitted once.
    let one = ["baselines", "--mode", "kfold:3", "--k", "1", "--methods", "pca", "--measures"];
    let mut args = one.to_vec();
    args.extend(["mapped_mse", "--data", d, "--out", "res1", "--fold", "1"]);
    let out = util::run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let csv = std::fs::read_to_string(dir.path().join("res1").join("results.csv")).unwrap();
    let mut only: Vec<String> =
        csv.lines().skip(1).map(|l| l.split(',').collect::<Vec<_>>()[2..4].join("\t")).collect();
    only.sort();
    let mut fold1 = fold1;
    fold1.sort();
    assert_eq!(only, fold1);
    let summary = std::fs::read_to_string(dir.path().join("res1").join("summary.md")).unwrap();
    assert!(summary.contains("fold 1 only"), "{summary}");
    let mut args = one.to_vec();
    args.extend(["mapped_mse", "--data", d, "--out", "res3", "--fold", "3"]);
    util::assert_clean_failure(&util::run_in(dir.path(), &args), "fold 3 does not exist");
    let out = util::run_in(dir.path(), &["baselines", "--k", "1", "--data", d, "--fold", "0"]);
    util::assert_clean_failure(&out, "kfold mode only");
}

/// Sun et al. 2018's separation runs beside the others: its row in the table, its error
/// falling with k, and a k with no specular coefficient refused with the reason.
#[test]
fn baselines_runs_sun2018_beside_ipca() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 5);
    let data = data.to_str().unwrap();
    let args = ["baselines", "--data", data, "--k", "2,4", "--methods", "ipca,sun2018"];
    let out = util::run_in(dir.path(), &[&args[..], &["--out", "res"]].concat());
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    let row = text.lines().find(|l| l.starts_with("| Sun2018 |")).unwrap_or_default();
    let errors: Vec<f64> =
        row.trim_matches('|').split('|').skip(1).filter_map(|f| f.trim().parse().ok()).collect();
    assert!(errors.len() >= 2 && errors[1] < errors[0], "{text}");
    let rows = read_results(&dir.path().join("res/results.csv"));
    assert!(rows.keys().any(|(m, k, _, _)| m == "Sun2018" && *k == 4), "no Sun2018 rows");

    let out = util::run_in(
        dir.path(),
        &["baselines", "--data", data, "--k", "1", "--methods", "sun2018", "--out", "res2"],
    );
    assert!(!out.status.success());
    let err = util::stderr(&out);
    assert!(err.contains("k = 1") && err.contains("no specular"), "{err}");
}

#[test]
fn baselines_train_the_deepbrdf_method_from_a_configuration_file() {
    // A narrow Table 1 (mean offset, standardised, warm-up) from a file, k set per --k; a
    // second run loads the finished models instead of training again.
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    write_materials(&data, 3);
    let config = serde_json::json!({
        "batch_size": 2, "checkpoint_seconds": 60.0, "epochs": 2, "final_lr_factor": 0.5,
        "learning_rate": 1e-3, "warmup_epochs": 1.0, "seed": 0, "threads": 1,
        "slice_dropout": null,
        "model": {"latent": 7, "negative_slope": 0.01, "architecture": {"convolutional": {
            "projection": 2, "encoder_channels": [2, 2, 2], "residual_blocks": 1,
            "decoder_channels": [2, 2], "mean_offset": true, "he_init": true,
            "standardise": true, "conv": "gemm"}}},
        "optimizer": {"amsgrad": false, "beta_1": 0.9, "beta_2": 0.999, "epsilon": 1e-8,
            "grad_clipping": null, "weight_decay": null}
    });
    std::fs::write(dir.path().join("c.json"), config.to_string()).unwrap();
    let data = data.to_str().unwrap();
    let args = [
        "baselines",
        "--data",
        data,
        "--k",
        "1,2",
        "--methods",
        "pca,deepbrdf",
        "--config",
        "c.json",
        "--measures",
        "mapped_mse",
        "--out",
        "res",
    ];
    let out = util::run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let rows = read_results(&dir.path().join("res/results.csv"));
    for k in [1, 2] {
        let key = ("DeepBRDF".to_string(), k, "material-0".to_string(), "mapped_mse".to_string());
        assert!(rows.get(&key).is_some_and(|v| v.is_finite()), "{k}: {rows:?}");
        let saved = dir.path().join(format!("res/models/fold0/k{k}/train_config.json"));
        let saved: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(saved).unwrap()).unwrap();
        assert_eq!(saved["model"]["latent"], k);
        assert_eq!(saved["warmup_epochs"], 1.0);
    }
    let again = util::run_in(dir.path(), &[&args[..], &["--force"]].concat());
    assert!(again.status.success(), "{}", util::stderr(&again));
    util::assert_clean_failure(
        &util::run_in(
            dir.path(),
            &["baselines", "--data", data, "--config", "missing.json", "--methods", "deepbrdf"],
        ),
        "missing.json",
    );
}

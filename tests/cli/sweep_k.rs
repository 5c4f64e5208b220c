//! `experiments sweep-k` end to end on a tiny configuration: three synthetic MERL files, a
//! two-channel network trained for one epoch, k = 1 and 2. The second run must reuse the
//! trained models (and so reproduce the first run's numbers exactly).
use crate::util;
use deepbrdf_data::augment::{kept_slices, SliceSelection};
use deepbrdf_data::MerlTable;
use deepbrdf_eval::harness::{Measure, Yardstick};
use deepbrdf_model::autoencoder::{Architecture, ConvolutionalConfig};
use deepbrdf_model::burn::config::Config as _;
use deepbrdf_model::{AutoencoderConfig, TrainConfig};
use std::collections::BTreeMap;
use std::path::Path;

fn tiny_config(path: &Path) {
    let layers = ConvolutionalConfig::new()
        .with_projection(Some(2))
        .with_encoder_channels([2, 2, 2])
        .with_residual_blocks(0)
        .with_decoder_channels([2, 2])
        .with_mean_offset(true);
    let model = AutoencoderConfig::convolutional(2, layers);
    let mut config = TrainConfig::slice(2).with_epochs(1).with_batch_size(4);
    config.model = model;
    config.save(path).expect("writing the training configuration");
}

/// `sweep-k` on `data` at k = 1, 2 (DeepBRDF at both) with the training configuration
/// `config` into `out`, the Fig. 2 picture of m1, in-sample unless `extra` names a mode, then
/// `extra`.
fn sweep_args(data: &Path, config: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let mut args: Vec<String> = ["sweep-k", "--data", &s(data), "--ks", "1,2", "--deep-ks", "all"]
        .into_iter()
        .chain(["--train-config", &s(config), "--out", &s(out), "--fig2-material", "m1"])
        .map(str::to_string)
        .collect();
    if !extra.contains(&"--mode") {
        args.extend(["--mode".to_string(), "in-sample".to_string()]);
    }
    args.extend(extra.iter().map(|a| a.to_string()));
    args
}

#[test]
fn sweep_k_writes_results_and_reuses_trained_models() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let config = dir.path().join("tiny.json");
    tiny_config(&config);
    let readme = dir.path().join("README.md");
    let held_out = "<!-- sweep-k:begin -->\nheld out\n<!-- sweep-k:end -->\n";
    let in_sample =
        "<!-- sweep-k-in-sample:begin -->\nstale block\n<!-- sweep-k-in-sample:end -->\n";
    std::fs::write(&readme, format!("# x\n{in_sample}{held_out}end\n")).unwrap();
    let out = dir.path().join("out");
    let readme_arg = readme.to_str().unwrap().to_string();
    let args =
        sweep_args(&data, &config, &out, &["--fig2-ks", "1,2", "--update-readme", &readme_arg]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();

    let first = util::run_in(dir.path(), &args);
    assert!(first.status.success(), "{}", util::stderr(&first));
    let text = util::stdout(&first);
    assert!(text.contains("| DeepBRDF |") && text.contains("nearest-slice fill"), "{text}");
    for f in [
        "results.csv",
        "summary.md",
        "error_vs_k_mapped_mse.svg",
        "per_material_mapped_mse.svg",
        "robustness.csv",
        "robustness.svg",
        "fig2_slices.png",
        "training.csv",
        "models/fold0/k1/model/model.json",
        "models/fold0/k2/model/model.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let results = std::fs::read_to_string(out.join("results.csv")).unwrap();
    // 3 methods x 2 k x 3 materials x 5 measures (mapped, cosine-weighted, image RelAE, dark
    // holes, tinted centres), plus the header.
    assert_eq!(results.lines().count(), 1 + 3 * 2 * 3 * 5, "{results}");
    assert!(out.join("per_material_image_relae.svg").is_file());
    let training = std::fs::read_to_string(out.join("training.csv")).unwrap();
    assert_eq!(training.lines().filter(|l| l.contains(",trained,")).count(), 2, "{training}");
    let first_training = training;
    let robustness = std::fs::read_to_string(out.join("robustness.csv")).unwrap();
    // Per material: DeepBRDF from all slices at 2 k, and per reduced input (2) the fill and 2 k.
    assert_eq!(robustness.lines().count(), 1 + 3 * (2 + 2 * 3), "{robustness}");
    let md = std::fs::read_to_string(&readme).unwrap();
    // The in-sample run rewrites its own block and leaves the held-out one alone.
    assert!(
        md.starts_with("# x\n<!-- sweep-k-in-sample:begin -->\n")
            && md.ends_with(&format!("<!-- sweep-k-in-sample:end -->\n{held_out}end\n")),
        "{md}"
    );
    assert!(md.contains("**In-sample**"), "{md}");
    assert!(
        md.contains("| IPCA |")
            && md.contains("out/error_vs_k_mapped_mse.svg")
            && !md.contains("stale block"),
        "{md}"
    );

    // Run again: the finished models are reused (loaded, or taken from their finished
    // checkpoints), not trained again, and give the same numbers.
    let second = util::run_in(dir.path(), &args);
    assert!(second.status.success(), "{}", util::stderr(&second));
    let training = std::fs::read_to_string(out.join("training.csv")).unwrap();
    // The training seconds recorded with each model (column 5) are those of the first run.
    let recorded = |csv: &str| -> Vec<String> {
        csv.lines().skip(1).map(|l| l.split(',').nth(4).unwrap_or_default().to_string()).collect()
    };
    assert_eq!(recorded(&training), recorded(&first_training), "{first_training}\n{training}");
    assert_eq!(std::fs::read_to_string(out.join("results.csv")).unwrap(), results);
}

/// The default run is held out: 5-fold, PCA and IPCA at every k, DeepBRDF at one (the middle
/// k when 10 is not swept), every material scored by methods that never saw it, and the
/// summary says so before any number.
#[test]
fn sweep_k_by_default_is_held_out_with_deepbrdf_at_one_k() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 6);
    let config = dir.path().join("tiny.json");
    tiny_config(&config);
    let out = dir.path().join("out");
    let (data, config, out_arg) = (util::s(&data), util::s(&config), util::s(&out));
    let args = ["sweep-k", "--data", &data, "--ks", "1,2,3", "--train-config", &config];
    let mut args: Vec<&str> = args.into_iter().chain(["--out", &out_arg]).collect();
    args.extend(["--measures", "mapped_mse", "--fig2-material", "m1"]);
    let o = util::run_in(dir.path(), &args);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let rows = rows(&std::fs::read_to_string(out.join("results.csv")).unwrap());
    // PCA and IPCA: 3 k x 6 materials; DeepBRDF: k = 2 only.
    assert_eq!(rows.len(), 2 * 3 * 6 + 6, "{rows:?}");
    assert!(rows.iter().filter(|r| r.0 == "DeepBRDF").all(|r| r.1 == 2));
    let training = std::fs::read_to_string(out.join("training.csv")).unwrap();
    assert_eq!(training.lines().filter(|l| l.contains(",trained,")).count(), 5, "{training}");
    for fold in 0..5 {
        assert!(out.join(format!("models/fold{fold}/k2/model/model.json")).is_file());
    }
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let held_out = summary.find("**Held out**: 5-fold").expect(&summary);
    let first_number = summary.find("- k = 2, ").expect(&summary);
    assert!(held_out < first_number, "{summary}");
    assert!(summary.contains("DeepBRDF at k = 2 vs PCA and IPCA at k = 3"), "{summary}");
    let stdout = util::stdout(&o);
    assert!(stdout.contains("**Held out**") && stdout.contains("| DeepBRDF | - |"), "{stdout}");
    // A DeepBRDF k outside the swept ones is refused before anything is trained.
    let bad: Vec<&str> = args.iter().copied().chain(["--deep-ks", "4"]).collect();
    util::assert_clean_failure(&util::run_in(dir.path(), &bad), "--deep-ks: k = 4");
}

#[test]
fn sweep_k_in_generalize_mode_scores_another_collection() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let config = dir.path().join("tiny.json");
    tiny_config(&config);
    let out = dir.path().join("out");
    let cache = dir.path().join("cache");
    let args = sweep_args(
        &data,
        &config,
        &out,
        &["--mode", "generalize", "--eval-collections", "nielsen2015", "--measures"],
    );
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    let cache = cache.to_str().unwrap();
    args.extend(["mapped_mse", "--fig2-ks", "2", "--cache", cache]);
    let o = util::run_in(dir.path(), &args);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let results = std::fs::read_to_string(out.join("results.csv")).unwrap();
    // 3 methods x 2 k x the 8 nielsen2015 materials, one measure; none of the training ones.
    assert_eq!(results.lines().count(), 1 + 3 * 2 * 8, "{results}");
    assert!(results.contains(",bluebook,") && !results.contains(",m1,"), "{results}");
    let robustness = std::fs::read_to_string(out.join("robustness.csv")).unwrap();
    // Per material: DeepBRDF from all slices (k = 2), and per reduced input the fill and k = 2.
    assert_eq!(robustness.lines().count(), 1 + 8 * (1 + 2 * 2), "{robustness}");
}

#[test]
fn sweep_k_refuses_bad_settings_cleanly() {
    let out = util::run(&["sweep-k", "--ks", "0,5"]);
    util::assert_clean_failure(&out, "k values");
    let out = util::run(&["sweep-k", "--eval-collections", "nielsen2015"]);
    util::assert_clean_failure(&out, "generalize mode only");
    let out = util::run(&["sweep-k", "--data", "/nonexistent/folder", "--epochs", "1"]);
    util::assert_clean_failure(&out, "/nonexistent/folder");
}

/// The `slice` preset's network and training, shrunk ([`util::tiny_train_config`]) to 5
/// epochs for three materials, with a slice basis of 32 directions (what it cannot represent
/// bounds the error at every k).
fn slice_config(path: &Path) {
    let mut config = util::tiny_train_config().with_epochs(5);
    if let Architecture::Slice(layers) = &mut config.model.architecture {
        layers.directions = 32;
    }
    config.save(path).expect("writing the training configuration");
}

/// `results.csv` as rows of (method, k, material, measure, value).
fn rows(csv: &str) -> Vec<(String, usize, String, String, f64)> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("method,k,fold,material,measure,value"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 6, "{l}");
            (f[0].into(), f[1].parse().unwrap(), f[3].into(), f[4].into(), f[5].parse().unwrap())
        })
        .collect()
}

#[test]
fn sweep_k_with_the_slice_preset_network_beats_pca_and_is_thread_count_independent() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let config = dir.path().join("slice.json");
    slice_config(&config);
    let mut outputs = Vec::new();
    for (threads, out) in [(1, "one"), (3, "three")] {
        let out = dir.path().join(out);
        let extra = ["--measures", "mapped_mse,cos_rmse", "--fig2-ks", "2"];
        let args = sweep_args(&data, &config, &out, &extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = util::run_on_threads(dir.path(), &args, threads);
        assert!(run.status.success(), "{}", util::stderr(&run));
        assert!(out.join("models/fold0/k2/model/model.json").is_file(), "a trained model");
        outputs.push((
            std::fs::read(out.join("results.csv")).unwrap(),
            std::fs::read(out.join("robustness.csv")).unwrap(),
        ));
    }
    assert!(outputs[0].0 == outputs[1].0, "results.csv differs between 1 and 3 threads");
    assert!(outputs[0].1 == outputs[1].1, "robustness.csv differs between 1 and 3 threads");

    // Three materials lie in a 2-dimensional affine span: at k = 2 the slice network (an
    // untrained one is PCA in the mapped space within its slice basis' span) reconstructs them
    // in the eq. (1) space well below its k = 1 error, down to what the basis cannot
    // represent, and at both k below PCA at k = 1.
    let rows = rows(std::str::from_utf8(&outputs[0].0).unwrap());
    assert_eq!(rows.len(), 3 * 2 * 3 * 2, "methods x k x materials x measures");
    let mean = |method: &str, k: usize| {
        let v: Vec<f64> = rows
            .iter()
            .filter(|r| r.0 == method && r.1 == k && r.3 == "mapped_mse")
            .map(|r| r.4)
            .collect();
        assert_eq!(v.len(), 3, "{method} k = {k}");
        v.iter().sum::<f64>() / 3.0
    };
    let (deep1, deep2, pca1) = (mean("DeepBRDF", 1), mean("DeepBRDF", 2), mean("PCA", 1));
    assert!(deep2 < 0.5 * deep1, "DeepBRDF k = 1: {deep1}, k = 2: {deep2}");
    assert!(deep1 < pca1, "DeepBRDF k = 1: {deep1}, PCA k = 1: {pca1}");
    assert!(rows.iter().all(|r| r.4.is_finite() && r.4 >= 0.0));

    // robustness.csv: DeepBRDF from all slices repeats results.csv; the nearest-slice fill is
    // the harness's mapped MSE of the filled table, computed here directly, and grows as fewer
    // slices are kept.
    let robustness = String::from_utf8(outputs[0].1.clone()).unwrap();
    let mut lines = robustness.lines();
    assert_eq!(lines.next(), Some("input,method,k,fold,material,mapped_mse"));
    let records: Vec<Vec<String>> =
        lines.map(|l| l.split(',').map(str::to_string).collect()).collect();
    let tables: Vec<MerlTable> = (0..3).map(util::material).collect();
    let refs: Vec<&MerlTable> = tables.iter().collect();
    let yardstick = Yardstick::from_training(&refs).unwrap();
    let mut fills = BTreeMap::new();
    for r in &records {
        let value: f64 = r[5].parse().unwrap();
        let i: usize = r[4].trim_start_matches('m').parse().unwrap();
        match (r[0].as_str(), r[1].as_str()) {
            ("1/1", "DeepBRDF") => {
                let k: usize = r[2].parse().unwrap();
                let full = rows
                    .iter()
                    .find(|x| x.0 == "DeepBRDF" && x.1 == k && x.2 == r[4] && x.3 == "mapped_mse")
                    .unwrap();
                assert_eq!(value, full.4, "{r:?}");
            }
            (every, "nearest-slice fill") => {
                let n: usize = every.trim_start_matches("1/").parse().unwrap();
                let kept = kept_slices(&SliceSelection::Every(n), 0);
                let filled = tables[i].with_kept_slices(&kept);
                let want = yardstick
                    .measure(&yardstick.original(&tables[i]), &filled, &[Measure::MappedMse])
                    .unwrap()[0];
                assert_eq!(value, want, "{r:?}");
                fills.insert((i, n), value);
            }
            _ => {}
        }
    }
    assert_eq!(fills.len(), 3 * 2, "{robustness}");
    for i in 0..3 {
        assert!(0.0 < fills[&(i, 3)] && fills[&(i, 3)] < fills[&(i, 9)], "{fills:?}");
    }
}

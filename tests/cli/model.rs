//! `experiments train`, `encode`, `decode` and `reconstruct` end to end with a tiny `slice`
//! network (k = 2, [`util::tiny_train_config`]) on three synthetic MERL files: the commands
//! chain, a reconstruction of a training material comes back close, bad inputs are named, and
//! a model directory of a retired format is refused with what to do.
use crate::util;
use deepbrdf_data::merl::read_merl;
use deepbrdf_model::burn::config::Config as _;
use deepbrdf_model::TrainConfig;

use crate::util::s;

#[test]
fn train_encode_decode_and_reconstruct_a_slice_model() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let config = util::tiny_train_config().with_epochs(3);
    let config_path = dir.path().join("tiny.json");
    config.save(&config_path).unwrap();
    let run = dir.path().join("run");
    let ok = util::runner(dir.path());
    ok(&["train", "--config", &s(&config_path), "--data", &s(&data), "--out", &s(&run)]);

    let m1 = s(&data.join("m1.binary"));
    let latent = dir.path().join("m1.json");
    ok(&["encode", &s(&run), &m1, "-o", &s(&latent)]);
    assert!(std::fs::read_to_string(&latent).unwrap().contains(','), "two latent values");
    // `--model DIR` is the same model as the positional form; both at once are refused.
    let positional = ok(&["encode", &s(&run), &m1]).stdout;
    assert_eq!(ok(&["encode", "--model", &s(&run), &m1]).stdout, positional);
    let out = util::run_in(dir.path(), &["encode", "--model", &s(&run), &s(&run), &m1]);
    util::assert_clean_failure(&out, "give the model once");
    let decoded_path = dir.path().join("m1-decoded.binary");
    ok(&["decode", &s(&run), &s(&latent), "-o", &s(&decoded_path)]);
    let original = util::material(1);
    let decoded = read_merl(&decoded_path).unwrap();
    assert_eq!(decoded.mask(), original.mask());
    // Three materials span two directions around their mean: k = 2 holds a training material
    // up to what the 8-direction slice basis loses and three epochs of the MLPs (which start
    // at zero).
    let mut errors: Vec<f32> = original
        .values()
        .iter()
        .zip(decoded.values())
        .filter(|(o, _)| **o > 0.0)
        .map(|(o, d)| (d - o).abs() / o)
        .collect();
    errors.sort_by(f32::total_cmp);
    let median = errors[errors.len() / 2];
    assert!(median < 0.02, "median relative error {median}");

    let reconstructed = dir.path().join("m1-ninth.binary");
    ok(&["reconstruct", &s(&run), &m1, "-o", &s(&reconstructed), "--slices", "1/9"]);
    assert_eq!(read_merl(&reconstructed).unwrap().mask(), original.mask());

    // A latent vector made by another model is refused, naming both, unless --force; one of
    // the wrong length is refused even then.
    let text = std::fs::read_to_string(&latent).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let own_id = value["model_id"].as_str().unwrap().to_string();
    let foreign = dir.path().join("foreign.json");
    std::fs::write(&foreign, text.replace(&own_id, "0123456789abcdef")).unwrap();
    let out = util::run_in(dir.path(), &["decode", &s(&run), &s(&foreign), "-o", "foreign.binary"]);
    util::assert_clean_failure(&out, "made by model 0123456789abcdef");
    util::assert_clean_failure(&out, &own_id);
    assert!(!dir.path().join("foreign.binary").exists(), "nothing written on refusal");
    ok(&["decode", &s(&run), &s(&foreign), "-o", "foreign.binary", "--force"]);
    assert_eq!(
        read_merl(dir.path().join("foreign.binary")).unwrap(),
        read_merl(&decoded_path).unwrap()
    );
    let mut long = value.clone();
    long["latent"] = serde_json::json!([0.1, 0.2, 0.3]);
    long["k"] = serde_json::json!(3);
    let long_path = dir.path().join("long.json");
    std::fs::write(&long_path, long.to_string()).unwrap();
    let out = util::run_in(
        dir.path(),
        &["decode", &s(&run), &s(&long_path), "-o", "long.binary", "--force"],
    );
    util::assert_clean_failure(&out, "k = 2");

    let missing = s(&dir.path().join("missing.json"));
    let out = util::run_in(dir.path(), &["decode", &s(&run), &missing, "-o", "x.binary"]);
    util::assert_clean_failure(&out, "missing.json");
    let weights = run.join("model").join("weights.bpk");
    let mut bytes = std::fs::read(&weights).unwrap();
    bytes[100] ^= 0xff;
    std::fs::write(&weights, bytes).unwrap();
    let out = util::run_in(dir.path(), &["encode", &s(&run), &m1]);
    util::assert_clean_failure(&out, "weights.bpk");
}

#[test]
fn a_model_of_the_retired_cpu_preset_is_refused_with_what_to_do() {
    // A minimal manifest as the `cpu` preset's models had it: the spectral network's
    // configuration and its compact basis part.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("old").join("model");
    std::fs::create_dir_all(&model).unwrap();
    let part = serde_json::json!({"file": "weights.bpk", "bytes": 1, "sha256": "00"});
    let manifest = serde_json::json!({
        "format": "deepbrdf-model", "version": 2, "id": "0123456789abcdef",
        "config": {"latent": 10, "negative_slope": 0.01,
            "architecture": {"spectral": {"directions": 96, "hidden": 256, "he_init": true}}},
        "provenance": {"data_label": "merl", "materials": [], "data_fingerprint": "",
            "train_config": null, "seed": 0, "epochs": 1000, "final_loss": 0.0,
            "final_mse": 0.0, "train_seconds": 0.0, "device": "cpu"},
        "weights": part, "reference": part,
        "basis": {"file": "basis.f16", "bytes": 1, "sha256": "00"}});
    std::fs::write(model.join("model.json"), manifest.to_string()).unwrap();
    let m0 = util::write_data(dir.path(), 1).join("m0.binary");
    let out = util::run_in(dir.path(), &["encode", &s(&dir.path().join("old")), &s(&m0)]);
    util::assert_clean_failure(&out, &s(&model));
    util::assert_clean_failure(&out, "retired format");
    util::assert_clean_failure(&out, "--preset slice");
    let out = util::run_in(dir.path(), &["train", "--preset", "cpu", "--out", "x"]);
    util::assert_clean_failure(&out, "retired");
}

#[test]
fn train_names_a_bad_config_file_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 1);
    let saved = dir.path().join("saved.json");
    TrainConfig::slice(2).save(&saved).unwrap();
    let mut good: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&saved).unwrap()).unwrap();
    assert!(good.get("epochs").is_some(), "{good}");
    good["epochs"] = serde_json::json!("many");
    let cases = [
        ("broken.json", "{ \"epochs\": 3,".to_string(), "broken.json"),
        ("wrong-type.json", good.to_string(), "wrong-type.json"),
        ("empty.json", String::new(), "empty.json"),
    ];
    for (name, text, needle) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let run = dir.path().join(format!("run-{name}"));
        let out = util::run_in(
            dir.path(),
            &["train", "--config", &s(&path), "--data", &s(&data), "--out", &s(&run)],
        );
        util::assert_clean_failure(&out, needle);
        util::assert_clean_failure(&out, "not a training configuration");
        assert!(!run.exists(), "{name}: a run folder was created");
    }
    let missing = dir.path().join("missing.json");
    let out = util::run_in(
        dir.path(),
        &["train", "--config", &s(&missing), "--data", &s(&data), "--out", "run"],
    );
    util::assert_clean_failure(&out, "missing.json");
}

#[test]
fn bench_model_prints_the_decode_time_next_to_ipcas() {
    let out = util::run(&[
        "bench",
        "model",
        "--preset",
        "slice",
        "--k",
        "3",
        "--steps",
        "1",
        "--decodes",
        "1",
    ]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    let line =
        text.lines().find(|l| l.contains("decode vs IPCA's at k = 3")).unwrap_or_else(|| {
            panic!("no decode comparison: {text}");
        });
    // "... A s vs B s (Rx, same run)": both times positive, the ratio theirs.
    let numbers: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let [_, deep, ipca, ratio] = numbers[..] else { panic!("{line}") };
    assert!(deep > 0.0 && ipca > 0.0, "{line}");
    assert!((ratio - deep / ipca).abs() <= 0.01 + 0.01 * ratio, "{line}");
}

#[test]
fn bench_model_writes_the_readmes_decode_row_from_its_own_run() {
    let dir = tempfile::tempdir().unwrap();
    let readme = dir.path().join("README.md");
    let text =
        "# T\n\nbefore\n<!-- bench-decode:begin -->\nold row\n<!-- bench-decode:end -->\nafter\n";
    std::fs::write(&readme, text).unwrap();
    let path = readme.to_str().unwrap();
    let args =
        ["bench", "model", "--preset", "slice", "--k", "3", "--steps", "1", "--decodes", "1"];
    let mut with_readme = args.to_vec();
    with_readme.extend(["--update-readme", path]);
    let out = util::run_ok(dir.path(), &with_readme);
    let printed = util::stdout(&out);
    let line = printed.lines().find(|l| l.contains("decode vs IPCA's")).expect("a decode line");
    let times: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let written = std::fs::read_to_string(&readme).unwrap();
    assert!(written.starts_with("# T\n\nbefore\n<!-- bench-decode:begin -->\n"), "{written}");
    assert!(written.ends_with("<!-- bench-decode:end -->\nafter\n"), "{written}");
    assert!(!written.contains("old row"), "{written}");
    // The block's numbers are this run's (3 decimals of the printed 4).
    let [_, deep, ipca, _] = times[..] else { panic!("{line}") };
    let row = written.lines().find(|l| l.contains(" s / ")).expect("the measured row");
    let cell = row.split('|').find(|c| c.contains(" s / ")).unwrap();
    let block: Vec<f64> = cell
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!((block[0] - deep).abs() <= 6e-4 && (block[1] - ipca).abs() <= 6e-4, "{row} vs {line}");
    assert!(written.contains("--k 3 --steps 1 --decodes 1 --update-readme README.md"), "{written}");
    // The paper preset has no decode row to write.
    let mut paper = vec!["bench", "model", "--preset", "paper", "--update-readme", path];
    paper.extend(["--steps", "1"]);
    util::assert_clean_failure(&util::run_in(dir.path(), &paper), "--preset slice");
}

#[test]
fn bench_model_times_both_convolution_algorithms_of_a_convolutional_network() {
    use deepbrdf_model::autoencoder::ConvolutionalConfig;
    use deepbrdf_model::AutoencoderConfig;
    let dir = tempfile::tempdir().unwrap();
    let layers = ConvolutionalConfig::new()
        .with_projection(Some(2))
        .with_encoder_channels([2, 2, 2])
        .with_residual_blocks(1)
        .with_decoder_channels([2, 2]);
    let config = TrainConfig::new(
        AutoencoderConfig::convolutional(2, layers),
        deepbrdf_model::burn::optim::AdamConfig::new(),
    )
    .with_batch_size(1);
    let path = dir.path().join("narrow.json");
    config.save(&path).unwrap();
    let path = path.to_str().unwrap();
    let out = util::run(&[
        "bench",
        "model",
        "--config",
        path,
        "--conv",
        "direct,gemm",
        "--steps",
        "1",
        "--decodes",
        "1",
    ]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    for row in ["config/direct", "config/gemm", "config training step: direct / gemm = "] {
        assert!(text.lines().any(|l| l.starts_with(row)), "no line {row:?}: {text}");
    }
    // The slice network has no convolutions: --conv leaves its row alone, train refuses it.
    let out = util::run(&[
        "bench",
        "model",
        "--preset",
        "slice",
        "--k",
        "2",
        "--conv",
        "gemm",
        "--steps",
        "1",
        "--decodes",
        "1",
    ]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert!(util::stdout(&out).lines().any(|l| l.starts_with("slice ")), "{}", util::stdout(&out));
    let out =
        util::run_in(dir.path(), &["train", "--preset", "slice", "--conv", "gemm", "--out", "o"]);
    util::assert_clean_failure(&out, "no convolutions");
    let out =
        util::run_in(dir.path(), &["train", "--preset", "paper", "--conv", "fft", "--out", "o"]);
    util::assert_clean_failure(&out, "expected gemm or direct");
}

#[test]
fn the_configurations_in_configs_load_and_differ_from_the_slice_preset_only_in_its_network() {
    use deepbrdf_model::TrainConfig;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs");
    let mut seen = 0;
    let (mut table1, mut paths) = (0, Vec::new());
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        match path.is_dir() {
            // configs/table1-schedules: the schedules issue 57 compared.
            true => paths.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path())),
            false => paths.push(path),
        }
    }
    paths.sort();
    for path in paths {
        let config = TrainConfig::from_file(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        // Table 1's CPU schedules: the paper's layers, whatever the schedule.
        if let deepbrdf_model::autoencoder::Architecture::Convolutional(c) =
            &config.model.architecture
        {
            let paper = deepbrdf_model::autoencoder::AutoencoderConfig::paper(10);
            let deepbrdf_model::autoencoder::Architecture::Convolutional(p) = &paper.architecture
            else {
                panic!("the paper preset is convolutional")
            };
            assert_eq!(
                (c.projection, c.encoder_channels, c.residual_blocks, c.decoder_channels),
                (p.projection, p.encoder_channels, p.residual_blocks, p.decoder_channels),
                "{path:?}"
            );
            table1 += 1;
            continue;
        }
        let mut preset = TrainConfig::slice(config.model.latent);
        let slice = config.model.slice_config().expect("a slice configuration").clone();
        if let deepbrdf_model::autoencoder::Architecture::Slice(s) = &mut preset.model.architecture
        {
            assert_ne!(serde_json::to_value(&*s).unwrap(), serde_json::to_value(&slice).unwrap());
            *s = slice;
        }
        assert_eq!(serde_json::to_value(&preset).unwrap(), serde_json::to_value(&config).unwrap());
        seen += 1;
    }
    assert!(seen >= 2, "configs/ holds the ablation configurations");
    assert!(table1 >= 5, "configs/ holds Table 1's CPU schedules");
}

#[test]
fn train_within_a_time_limit_writes_the_epochs_done_and_resumes_to_the_end() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let config = util::tiny_config(dir.path());
    let run = dir.path().join("run");
    let args = ["train", "--config", &s(&config), "--data", &s(&data), "--out", &s(&run)];
    // Any epoch ends past a limit of a nanosecond: one epoch of the two, a model, a checkpoint.
    let out = util::run_in(dir.path(), &[&args[..], &["--time-limit", "1e-9"]].concat());
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    assert!(text.contains("stopped at the time limit after 1 of 2 epochs"), "{text}");
    let model: serde_json::Value =
        serde_json::from_slice(&std::fs::read(run.join("model").join("model.json")).unwrap())
            .unwrap();
    assert_eq!(model["provenance"]["epochs"], 1, "{model}");
    let out = util::run_in(dir.path(), &["train", "--resume", &s(&run), "--data", &s(&data)]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert!(util::stdout(&out).contains("trained 2 epochs"), "{}", util::stdout(&out));
    for bad in ["0", "-1", "soon"] {
        let limit = format!("--time-limit={bad}");
        let out = util::run_in(dir.path(), &[&args[..], &[limit.as_str()]].concat());
        util::assert_clean_failure(&out, "--time-limit");
    }
}

#[test]
fn highlights_reports_each_stage_of_a_model_trained_with_a_flattened_reference() {
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_model::autoencoder::Architecture;
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    // The tiny slice network with the highlight's centre weighted and the eq. (1) reference's
    // peak flattened below 10 deg.
    let mut config = util::tiny_train_config();
    if let Architecture::Slice(layers) = &mut config.model.architecture {
        layers.centre_emphasis = Some(5.0);
        layers.reference_flat_below_deg = Some(10.0);
    }
    let path = dir.path().join("centre.json");
    config.save(&path).unwrap();
    let model = dir.path().join("run");
    util::run_ok(
        dir.path(),
        &["train", "--config", &s(&path), "--data", &s(&data), "--out", &s(&model)],
    );
    // The model keeps the reference it was trained with: the training median, flattened.
    let tables: Vec<_> =
        (0..3).map(|i| read_merl(data.join(format!("m{i}.binary"))).unwrap()).collect();
    let refs: Vec<&_> = tables.iter().collect();
    let flat = MedianReference::from_tables(&refs).unwrap().flattened_below(10.0);
    let device = deepbrdf_model::DeviceKind::default_kind().unwrap().device().unwrap();
    let loaded = deepbrdf_model::DeepBrdf::load(&model, &device).unwrap();
    assert!(loaded.reference() == &flat, "the saved reference is not the flattened median");
    // One row per stage, each counting at most the 3 materials.
    let out = util::run_ok(dir.path(), &["highlights", "--model", &s(&model), "--data", &s(&data)]);
    let text = util::stdout(&out);
    assert!(text.contains("either (of 3)"), "{text}");
    for stage in ["basis", "linear", "encoded", "refined"] {
        let row = text.lines().find(|l| l.starts_with(&format!("| {stage} |"))).unwrap_or_default();
        let counts: Vec<usize> = row.split('|').filter_map(|c| c.trim().parse().ok()).collect();
        assert!(counts.len() == 3 && counts.iter().all(|&c| c <= 3), "{stage}: {row}");
    }
    // --profile: the reference, the original and the four stages at each theta_h sample.
    let m0 = s(&data.join("m0.binary"));
    let out = util::run_ok(dir.path(), &["highlights", "--model", &s(&model), "--profile", &m0]);
    let text = util::stdout(&out);
    let row = text.lines().find(|l| l.starts_with("| 0 |")).unwrap_or_default();
    assert_eq!(row.split('|').filter(|c| c.trim().parse::<f64>().is_ok()).count(), 8, "{text}");
    // A model that is not a slice network has no stages: a clear error.
    let paper = dir.path().join("paper.json");
    let mut conv = TrainConfig::paper(2).with_epochs(1).with_batch_size(2);
    conv.model = deepbrdf_model::AutoencoderConfig::convolutional(
        2,
        deepbrdf_model::autoencoder::ConvolutionalConfig::new()
            .with_projection(Some(1))
            .with_encoder_channels([1, 1, 1])
            .with_residual_blocks(0)
            .with_decoder_channels([1, 1]),
    );
    conv.save(&paper).unwrap();
    let conv_model = dir.path().join("conv");
    util::run_ok(
        dir.path(),
        &["train", "--config", &s(&paper), "--data", &s(&data), "--out", &s(&conv_model)],
    );
    let out =
        util::run_in(dir.path(), &["highlights", "--model", &s(&conv_model), "--data", &s(&data)]);
    util::assert_clean_failure(&out, "slice");
}

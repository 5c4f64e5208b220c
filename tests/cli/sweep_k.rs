//! `experiments sweep-k` end to end on a tiny configuration: three synthetic MERL files, a
//! two-channel network trained for one epoch, k = 1 and 2. The second run must reuse the
//! trained models (and so reproduce the first run's numbers exactly).
use crate::util;
use deepbrdf_data::merl::write_merl;
use deepbrdf_model::autoencoder::ConvolutionalConfig;
use deepbrdf_model::burn::config::Config as _;
use deepbrdf_model::{AutoencoderConfig, TrainConfig};
use std::path::Path;

fn tiny_config(path: &Path) {
    let layers = ConvolutionalConfig::new()
        .with_projection(Some(2))
        .with_encoder_channels([2, 2, 2])
        .with_residual_blocks(0)
        .with_decoder_channels([2, 2])
        .with_mean_offset(true);
    let model = AutoencoderConfig::convolutional(2, layers);
    let mut config = TrainConfig::cpu(2).with_epochs(1).with_batch_size(4);
    config.model = model;
    config.save(path).expect("writing the training configuration");
}

#[test]
fn sweep_k_writes_results_and_reuses_trained_models() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir(&data).unwrap();
    for i in 0..3 {
        write_merl(&util::material(i), data.join(format!("m{i}.binary"))).unwrap();
    }
    let config = dir.path().join("tiny.json");
    tiny_config(&config);
    let readme = dir.path().join("README.md");
    std::fs::write(&readme, "# x\n<!-- sweep-k:begin -->\nold\n<!-- sweep-k:end -->\nend\n")
        .unwrap();
    let out = dir.path().join("out");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let args = [
        "sweep-k".to_string(),
        "--data".into(),
        s(&data),
        "--ks".into(),
        "1,2".into(),
        "--train-config".into(),
        s(&config),
        "--out".into(),
        s(&out),
        "--fig2-ks".into(),
        "1,2".into(),
        "--fig2-material".into(),
        "m1".into(),
        "--update-readme".into(),
        s(&readme),
    ];
    let args: Vec<&str> = args.iter().map(|a| a.as_str()).collect();

    let first = util::run_in(dir.path(), &args);
    assert!(first.status.success(), "{}", util::stderr(&first));
    let text = util::stdout(&first);
    assert!(text.contains("| DeepBRDF |") && text.contains("nearest-slice fill"), "{text}");
    for f in [
        "results.csv",
        "summary.md",
        "error_vs_k_mapped_mse.png",
        "error_vs_k_mapped_mse.svg",
        "per_material_mapped_mse.png",
        "per_material_mapped_mse.svg",
        "robustness.csv",
        "robustness.png",
        "robustness.svg",
        "fig2_slices.png",
        "training.csv",
        "models/fold0/k1/model/model.json",
        "models/fold0/k2/model/model.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let results = std::fs::read_to_string(out.join("results.csv")).unwrap();
    // 3 methods x 2 k x 3 materials x 3 measures (mapped, cosine-weighted, image RelAE), plus
    // the header.
    assert_eq!(results.lines().count(), 1 + 3 * 2 * 3 * 3, "{results}");
    assert!(out.join("per_material_image_relae.png").is_file());
    let training = std::fs::read_to_string(out.join("training.csv")).unwrap();
    assert_eq!(training.lines().filter(|l| l.contains(",trained,")).count(), 2, "{training}");
    let first_training = training;
    let robustness = std::fs::read_to_string(out.join("robustness.csv")).unwrap();
    // Per material: DeepBRDF from all slices at 2 k, and per reduced input (2) the fill and 2 k.
    assert_eq!(robustness.lines().count(), 1 + 3 * (2 + 2 * 3), "{robustness}");
    let md = std::fs::read_to_string(&readme).unwrap();
    assert!(
        md.starts_with("# x\n<!-- sweep-k:begin -->\n")
            && md.ends_with("<!-- sweep-k:end -->\nend\n"),
        "{md}"
    );
    assert!(
        md.contains("| IPCA |")
            && md.contains("out/error_vs_k_mapped_mse.png")
            && !md.contains("old"),
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

#[test]
fn sweep_k_refuses_bad_settings_cleanly() {
    let out = util::run(&["sweep-k", "--ks", "0,5"]);
    util::assert_clean_failure(&out, "k values");
    let out = util::run(&["sweep-k", "--mode", "generalize"]);
    util::assert_clean_failure(&out, "in-sample or kfold");
    let out = util::run(&["sweep-k", "--data", "/nonexistent/folder", "--epochs", "1"]);
    util::assert_clean_failure(&out, "/nonexistent/folder");
}

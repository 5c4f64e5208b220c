//! `experiments train-regressor`, `edit`, `interpolate` and `bench edit` end to end with a tiny
//! `slice` model (k = 2, [`util::tiny_train_config`]) on three synthetic materials: the regressor is saved
//! naming its model, edits write MERL files and bad values are named, a regressor of another
//! model is refused.
use crate::util;
use deepbrdf_data::merl::read_merl;
use deepbrdf_model::burn::config::Config as _;

use crate::util::s;

#[test]
fn train_a_regressor_edit_and_interpolate() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let ok = util::runner(dir.path());
    let mut runs = Vec::new();
    for seed in [0u64, 1] {
        let config = util::tiny_train_config().with_seed(seed);
        let config_path = dir.path().join(format!("tiny{seed}.json"));
        config.save(&config_path).unwrap();
        let run = dir.path().join(format!("run{seed}"));
        ok(&["train", "--config", &s(&config_path), "--data", &s(&data), "--out", &s(&run)]);
        runs.push(run);
    }
    let (model, other) = (s(&runs[0]), s(&runs[1]));
    let printed = util::stdout(&ok(&[
        "train-regressor",
        "--model",
        &model,
        "--data",
        &s(&data),
        "--epochs",
        "30",
        "--ipca",
    ]));
    assert!(printed.contains("training relative error"), "{printed}");
    let regressor = runs[0].join("regressor");
    assert!(
        regressor.join("deepbrdf.regressor").is_file()
            && regressor.join("ipca.regressor").is_file()
    );
    // Not replaced without --force.
    let out = util::run_in(
        dir.path(),
        &["train-regressor", "--model", &model, "--data", &s(&data), "--epochs", "3"],
    );
    util::assert_clean_failure(&out, "--force");

    let m1 = s(&data.join("m1.binary"));
    for mode in ["paper", "residual"] {
        let edited = dir.path().join(format!("edited-{mode}.binary"));
        let printed = util::stdout(&ok(&[
            "edit",
            "--model",
            &model,
            &m1,
            "--diffuse-scale",
            "0.5",
            "--mode",
            mode,
            "-o",
            &s(&edited),
            "--render",
            &s(&dir.path().join(format!("{mode}.png"))),
            "--size",
            "16",
            "--spp",
            "1",
        ]));
        assert!(printed.contains("requested") && printed.contains("achieved"), "{printed}");
        assert_eq!(read_merl(&edited).unwrap().mask(), util::material(1).mask());
    }
    let edited = s(&dir.path().join("edited-paper.binary"));
    let out = util::run_in(
        dir.path(),
        &[
            "edit",
            "--model",
            &model,
            &m1,
            "--roughness-scale",
            "2",
            "--mode",
            "paper",
            "-o",
            &edited,
        ],
    );
    util::assert_clean_failure(&out, "--force");
    let bad = |args: &[&str], needle: &str| {
        let mut all = vec!["edit", "--model", &model, &m1, "--mode", "residual"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", "x.binary"]);
        let out = util::run_in(dir.path(), &all);
        util::assert_clean_failure(&out, needle);
        assert!(!dir.path().join("x.binary").exists());
    };
    bad(&["--diffuse", "1.5,0.1,0.1"], "outside [0, 1]");
    bad(&["--diffuse", "0.1,0.2"], "three numbers");
    bad(&["--roughness", "-0.1"], "positive");
    bad(&["--specular-scale", "-2"], ">= 0");
    // The regressor of model 0 with model 1: refused, naming both.
    let out = util::run_in(
        dir.path(),
        &[
            "edit",
            "--model",
            &other,
            "--regressor",
            &s(&regressor),
            &m1,
            "--diffuse-scale",
            "0.5",
            "--mode",
            "residual",
            "-o",
            "x.binary",
        ],
    );
    util::assert_clean_failure(&out, "belongs to DeepBRDF model");
    let out = util::run_in(
        dir.path(),
        &["edit", "--model", &other, &m1, "--mode", "transfer", "-o", "x.binary"],
    );
    util::assert_clean_failure(&out, "train-regressor");
    // A model given to the default (parts) edit, which uses none: refused, naming the modes.
    let out = util::run_in(dir.path(), &["edit", "--model", &model, &m1, "-o", "x.binary"]);
    util::assert_clean_failure(&out, "--mode residual");
    assert!(!dir.path().join("x.binary").exists());

    let strip = dir.path().join("interp");
    let printed = util::stdout(&ok(&[
        "interpolate",
        "--model",
        &model,
        &s(&data.join("m0.binary")),
        &m1,
        "--steps",
        "3",
        "--out",
        &s(&strip),
    ]));
    assert!(printed.contains("linear blend") && printed.contains("IPCA"), "{printed}");
    assert!(strip.join("strip.png").is_file() && strip.join("deepbrdf-02.binary").is_file());
    let printed = util::stdout(&ok(&["bench", "edit", "--model", &model, &m1, "--reps", "1"]));
    assert!(printed.contains("one edit:"), "{printed}");
}

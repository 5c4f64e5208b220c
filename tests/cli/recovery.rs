//! Single-image recovery end to end on tiny data: `render-set` (a few 16-px images of three
//! synthetic materials; resumed; a held-out fold), `train-recovery` (the small CNN for two
//! epochs on a tiny `slice` model), `recover` (a set image and unusable photos) and the
//! refusal of a network trained for another model.
use crate::util;
use deepbrdf_data::merl::read_merl;
use std::path::Path;

use crate::util::s;

#[test]
fn render_set_train_recovery_and_recover_chain() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let ok = util::runner(dir.path());
    // A tiny `slice` model (k = 2) on the three materials.
    let config_path = util::tiny_config(dir.path());
    let model = dir.path().join("model");
    ok(&["train", "--config", &s(&config_path), "--data", &s(&data), "--out", &s(&model)]);

    let set = dir.path().join("set");
    let render = |n: &str| {
        ok(&[
            "render-set",
            "--out",
            &s(&set),
            "--data",
            &s(&data),
            "--images",
            n,
            "--size",
            "16",
            "--spp",
            "2",
            "--seed",
            "4",
        ])
    };
    render("4");
    let first = std::fs::read(set.join("img-000001.png")).unwrap();
    std::fs::remove_file(set.join("img-000001.png")).unwrap();
    let out = render("6");
    assert!(util::stdout(&out).contains("3 rendered"), "{}", util::stdout(&out));
    assert_eq!(std::fs::read(set.join("img-000001.png")).unwrap(), first, "deterministic");
    // Other settings into the same folder are refused; a fold leaves its materials out.
    let other = util::run_in(
        dir.path(),
        &[
            "render-set",
            "--out",
            &s(&set),
            "--data",
            &s(&data),
            "--images",
            "6",
            "--size",
            "16",
            "--spp",
            "3",
        ],
    );
    util::assert_clean_failure(&other, "other settings");
    let held = dir.path().join("held");
    ok(&[
        "render-set",
        "--out",
        &s(&held),
        "--data",
        &s(&data),
        "--images",
        "2",
        "--size",
        "16",
        "--spp",
        "2",
        "--exclude-fold",
        "0/3",
    ]);
    let manifest = std::fs::read_to_string(held.join("manifest.json")).unwrap();
    let bad_fold = util::run_in(
        dir.path(),
        &[
            "render-set",
            "--out",
            &s(&dir.path().join("x")),
            "--data",
            &s(&data),
            "--exclude-fold",
            "3/3",
        ],
    );
    util::assert_clean_failure(&bad_fold, "I/N");
    assert!(manifest.contains("\"excluded\":[\"") && !manifest.contains("\"excluded\":[]"));

    // An image a camera could also give (nothing lit against the dark background) is skipped
    // with a note, not learnt from.
    deepbrdf_render::Srgb8Image::filled(16, 16, [0, 0, 0])
        .write_png(&set.join("img-000003.png"))
        .unwrap();
    let run = dir.path().join("cnn");
    let out = ok(&[
        "train-recovery",
        "--model",
        &s(&model),
        "--set",
        &s(&set),
        "--out",
        &s(&run),
        "--epochs",
        "2",
    ]);
    assert!(util::stdout(&out).contains("recovery CNN"), "{}", util::stdout(&out));
    assert!(
        util::stderr(&out).contains("1 of 6 images skipped as unusable (image 3: a blank image"),
        "{}",
        util::stderr(&out)
    );
    assert!(util::stdout(&out).contains("on 5 images"), "{}", util::stdout(&out));
    let net = run.join("recovery");
    assert!(net.join("recovery.json").is_file());
    let recovered = dir.path().join("r.binary");
    let compare = dir.path().join("c.png");
    let image = s(&set.join("img-000002.png"));
    ok(&[
        "recover",
        "--model",
        &s(&model),
        "--network",
        &s(&net),
        &image,
        "-o",
        &s(&recovered),
        "--render",
        &s(&compare),
    ]);
    assert_eq!(read_merl(&recovered).unwrap().mask(), util::material(0).mask());
    assert!(compare.is_file());

    // figures-recovery: the analytic baseline (7 outputs), a test set of the fold the `held`
    // set leaves out, every method measured in a novel scene.
    let attr = dir.path().join("cnn-attr");
    ok(&[
        "train-recovery",
        "--model",
        &s(&model),
        "--set",
        &s(&set),
        "--out",
        &s(&attr),
        "--epochs",
        "1",
        "--target",
        "attributes",
    ]);
    let test = dir.path().join("test");
    let test_args = ["--data", &s(&data), "--size", "16", "--spp", "2", "--only-fold", "0/3"];
    ok(&[&["render-set", "--out", &s(&test), "--images", "3", "--seed", "8"][..], &test_args]
        .concat());
    let figures = dir.path().join("figures");
    let fig_args = |train: &Path| {
        let mut a = vec!["figures-recovery".to_string(), "--model".into(), s(&model)];
        for (k, v) in [
            ("--network", s(&net)),
            ("--analytic", s(&attr.join("recovery"))),
            ("--train-set", s(train)),
            ("--test-set", s(&test)),
            ("--out", s(&figures)),
            ("--size", "16".into()),
            ("--spp", "2".into()),
            ("--nn-spp", "1".into()),
            ("--figure-size", "32".into()),
            ("--figure-spp", "2".into()),
        ] {
            a.push(k.into());
            a.push(v);
        }
        a
    };
    let args = fig_args(&held);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = ok(&args);
    let summary = std::fs::read_to_string(figures.join("summary.md")).unwrap();
    for method in ["deepbrdf", "analytic", "nearest", "mean"] {
        assert!(summary.contains(&format!("| held-out | 3 | 1 | {method} |")), "{summary}");
    }
    let csv = std::fs::read_to_string(figures.join("per_image.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(summary.contains("Render noise"), "{summary}");
    for f in ["fig16.jpg", "per_material_held-out.svg"] {
        assert!(figures.join(f).is_file(), "{f}: {}", util::stderr(&out));
    }
    // A test set that shares materials with the training set is not held out.
    let args = fig_args(&set);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    util::assert_clean_failure(&util::run_in(dir.path(), &args), "not held out");

    // Unusable photos: blank, not an image.
    let blank = dir.path().join("blank.png");
    deepbrdf_render::Srgb8Image::filled(32, 32, [0, 0, 0]).write_png(&blank).unwrap();
    let o = util::run_in(
        dir.path(),
        &[
            "recover",
            "--model",
            &s(&model),
            "--network",
            &s(&net),
            &s(&blank),
            "-o",
            &s(&recovered),
        ],
    );
    util::assert_clean_failure(&o, "blank");
    let junk = dir.path().join("junk.jpg");
    std::fs::write(&junk, b"no jpeg here").unwrap();
    let o = util::run_in(
        dir.path(),
        &["recover", "--model", &s(&model), "--network", &s(&net), &s(&junk), "-o", &s(&recovered)],
    );
    util::assert_clean_failure(&o, "junk.jpg");
    // A network trained for another model is refused.
    let other_model = dir.path().join("model2");
    ok(&[
        "train",
        "--config",
        &s(&config_path),
        "--data",
        &s(&data),
        "--out",
        &s(&other_model),
        "--seed",
        "9",
    ]);
    let o = util::run_in(
        dir.path(),
        &[
            "recover",
            "--model",
            &s(&other_model),
            "--network",
            &s(&net),
            &image,
            "-o",
            &s(&recovered),
        ],
    );
    util::assert_clean_failure(&o, "train-recovery");
    // The help states what a usable photo is.
    let help = util::stdout(&ok(&["recover", "--help"]));
    for needle in ["object", "centred", "sun-and-sky", "background", "alpha"] {
        assert!(help.contains(needle), "recover --help lacks '{needle}': {help}");
    }
}

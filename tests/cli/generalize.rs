//! `figures-generalize` (Fig. 9) and `figures-loss` (Fig. 4) on tiny data: models (and IPCA)
//! fitted on three synthetic materials, shown on two others; a model of other data without
//! `--ipca-data` is refused.
use crate::util;
use crate::util::s;

#[test]
fn figures_generalize_writes_fig9_with_both_methods_relae() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let shown = dir.path().join("shown");
    std::fs::create_dir(&shown).unwrap();
    for i in [3, 4] {
        deepbrdf_data::merl::write_merl(&util::material(i), shown.join(format!("n{i}.binary")))
            .unwrap();
    }
    let model = util::train_tiny(dir.path(), &data);

    let out = dir.path().join("fig9");
    let args = ["figures-generalize", "--model", &s(&model), "--data", &s(&shown)];
    let refused = util::run_in(dir.path(), &args);
    util::assert_clean_failure(&refused, "--ipca-data");
    let o = util::run_in(
        dir.path(),
        &[&args[..], &["--ipca-data", &s(&data), "--out", &s(&out), "--size", "64", "--spp", "4"]]
            .concat(),
    );
    assert!(o.status.success(), "{}", util::stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let csv = std::fs::read_to_string(out.join("fig9.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line.split(',').skip(1).map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite() && *x > 0.0), "{line}");
    }
    assert!(summary.contains("| n3 |") && summary.contains("**mean**"), "{summary}");
    assert!(out.join("fig9.jpg").is_file());

    // Fig. 8: Sun et al. 2018's separation as the baseline (fitted on four materials, the
    // fewest it takes), one material picked; a name not in the data is refused.
    let four = dir.path().join("four");
    std::fs::create_dir(&four).unwrap();
    for i in 0..4 {
        deepbrdf_data::merl::write_merl(&util::material(i), four.join(format!("m{i}.binary")))
            .unwrap();
    }
    let out = dir.path().join("fig8");
    let four = s(&four);
    let sun = [&args[..], &["--baseline", "sun2018", "--ipca-data", &four]].concat();
    let o = util::run_in(
        dir.path(),
        &[&sun[..], &["--materials", "n4", "--out", &s(&out), "--size", "64", "--spp", "4"]]
            .concat(),
    );
    assert!(o.status.success(), "{}", util::stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.starts_with("Fig. 8") && summary.contains("| Sun2018 |"), "{summary}");
    let csv = std::fs::read_to_string(out.join("fig8.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some("material,render_noise,relae_deepbrdf,relae_sun2018"));
    assert_eq!(csv.lines().count(), 2, "{csv}");
    assert!(csv.lines().nth(1).unwrap().starts_with("n4,"), "{csv}");
    assert!(out.join("fig8.jpg").is_file());
    let refused = util::run_in(dir.path(), &[&sun[..], &["--materials", "nope"]].concat());
    util::assert_clean_failure(&refused, "'nope' is not in");
}

/// `figures-loss` (Fig. 4): the same tiny network trained with `--loss l2` and `--loss l1`,
/// labelled from their configurations, shown on two materials neither saw (held out), then on
/// one of its training materials (in-sample, said so).
#[test]
fn figures_loss_compares_the_l2_and_l1_models() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 3);
    let shown = dir.path().join("shown");
    std::fs::create_dir(&shown).unwrap();
    for i in [3, 4] {
        deepbrdf_data::merl::write_merl(&util::material(i), shown.join(format!("n{i}.binary")))
            .unwrap();
    }
    let config = util::tiny_config(dir.path());
    let mut models = Vec::new();
    for norm in ["l2", "l1"] {
        let model = dir.path().join(norm);
        let o = util::run_in(
            dir.path(),
            &[
                "train",
                "--config",
                &s(&config),
                "--data",
                &s(&data),
                "--loss",
                norm,
                "--out",
                &s(&model),
            ],
        );
        assert!(o.status.success(), "{}", util::stderr(&o));
        models.push(s(&model));
    }
    let out = dir.path().join("fig4");
    let figure = |data: &std::path::Path| {
        util::run_in(
            dir.path(),
            &[
                "figures-loss",
                "--models",
                &models.join(","),
                "--data",
                &s(data),
                "--out",
                &s(&out),
                "--size",
                "32",
                "--spp",
                "2",
            ],
        )
    };
    let o = figure(&shown);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.contains("- L2: model") && summary.contains("- L1: model"), "{summary}");
    assert!(summary.contains("(held out)"), "{summary}");
    let csv = std::fs::read_to_string(out.join("fig4.csv")).unwrap();
    assert!(csv.starts_with("material,shown,render_noise,relae_l2,relae_l1\n"), "{csv}");
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(out.join("fig4.jpg").is_file());
    let o = figure(&data);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.contains("**in-sample**"), "{summary}");
    let refused =
        util::run_in(dir.path(), &["train", "--config", &s(&config), "--loss", "l3", "--out", "x"]);
    util::assert_clean_failure(&refused, "expected l2 or l1");
}

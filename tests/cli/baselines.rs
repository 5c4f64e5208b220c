//! `experiments baselines` end to end on a small folder of MERL files.
use crate::util;
use deepbrdf_data::merl::grid::theta_h_of;
use deepbrdf_data::merl::io::write_merl;
use deepbrdf_data::MerlTable;
use std::path::Path;

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
        "error_vs_k_mapped_mse.png",
        "per_material_cos_rmse.svg",
    ] {
        assert!(dir.path().join("res").join(f).is_file(), "{f} missing");
    }
    for f in ["PCA.basis", "IPCA.basis"] {
        assert!(dir.path().join("bases").join(f).is_file(), "{f} missing");
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

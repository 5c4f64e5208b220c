//! `experiments attributes` and the `ggx` method of `experiments baselines`, end to end on MERL
//! files tabulated from known Lambertian + GGX parameters.
use crate::util;
use deepbrdf_data::merl::io::write_merl;
use deepbrdf_eval::attributes::Attributes;
use std::path::Path;

/// Two analytic materials written as `a.binary`, `b.binary` into `dir`.
fn write_analytic(dir: &Path) -> [Attributes; 2] {
    let truth = [
        Attributes { diffuse: [0.4, 0.2, 0.1], specular: [0.05; 3], roughness: 0.1 },
        Attributes { diffuse: [0.02, 0.02, 0.03], specular: [0.9, 0.7, 0.4], roughness: 0.3 },
    ];
    std::fs::create_dir_all(dir).unwrap();
    for (name, t) in ["a", "b"].iter().zip(&truth) {
        write_merl(&t.table(), dir.join(format!("{name}.binary"))).unwrap();
    }
    truth
}

#[test]
fn attributes_recovers_analytic_materials_and_protects_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let truth = write_analytic(&dir.path().join("data"));
    let args = ["attributes", "data/a.binary", "data/b.binary", "-o", "out/attr.csv", "--relae"];
    let out = util::run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert!(util::stdout(&out).contains("2 materials"), "{}", util::stdout(&out));
    let csv = std::fs::read_to_string(dir.path().join("out/attr.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3, "{csv}");
    for (line, t) in lines[1..].iter().zip(&truth) {
        let v: Vec<&str> = line.split(',').collect();
        let got: Vec<f64> = v[1..8].iter().map(|s| s.parse().unwrap()).collect();
        // Written with 6 decimals and the MERL file's colour scaling round trip.
        for (g, w) in got.iter().zip(t.to_array()) {
            assert!((g - w).abs() <= 0.02 * w + 1e-5, "{line}: {g} vs {w}");
        }
        let relae: f64 = v[9].parse().unwrap();
        assert!(relae < 0.01, "the fit of an analytic material renders like it: {line}");
    }
    util::assert_clean_failure(&util::run_in(dir.path(), &args), "--force");
    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(util::run_in(dir.path(), &forced).status.success());
    std::fs::write(dir.path().join("bad.binary"), b"not a merl file").unwrap();
    let bad = util::run_in(dir.path(), &["attributes", "bad.binary", "-o", "x.csv"]);
    util::assert_clean_failure(&bad, "bad.binary");
    assert!(!dir.path().join("x.csv").exists());
}

#[test]
fn baselines_runs_the_ggx_method_at_k_7_only() {
    let dir = tempfile::tempdir().unwrap();
    write_analytic(&dir.path().join("data"));
    let args = ["baselines", "--data", "data", "--k", "7", "--methods", "ggx", "--out", "res"];
    let out = util::run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    assert!(text.contains("| GGX |") && text.contains("k = 7"), "{text}");
    let base = ["baselines", "--data", "data", "--out", "res2"];
    let wrong_k = [&base[..], &["--methods", "ggx", "--k", "5,7"]].concat();
    util::assert_clean_failure(&util::run_in(dir.path(), &wrong_k), "--k 7");
    let unknown = [&base[..], &["--methods", "pca,nbrdf"]].concat();
    util::assert_clean_failure(&util::run_in(dir.path(), &unknown), "unknown method 'nbrdf'");
}

//! `figures-quality` (Figs. 5 and 6) on tiny data: a model trained on four synthetic materials,
//! PCA and IPCA at k = 1 and 2, 32-px tiles; unknown materials, too many components and a
//! held-out figure with a model that saw its materials are refused.
use crate::util;
use crate::util::s;

#[test]
fn figures_quality_writes_figs_5_and_6_and_refuses_bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 4);
    let model = util::train_tiny(dir.path(), &data);

    let out = dir.path().join("figs");
    let (model, data, out_s) = (s(&model), s(&data), s(&out));
    let base = [
        "figures-quality",
        "--model",
        &model,
        "--data",
        &data,
        "--size",
        "32",
        "--spp",
        "2",
        "--labels",
        "2",
        "--out",
        &out_s,
    ];
    let run = |extra: &[&str]| {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        util::run_in(dir.path(), &args)
    };
    let unknown = run(&["--materials", "m0,nope", "--k", "1"]);
    util::assert_clean_failure(&unknown, "'nope' is not in");
    let too_many = run(&["--materials", "m0", "--k", "1,4"]);
    util::assert_clean_failure(&too_many, "at most 3 components");
    let seen = run(&["--materials", "m0", "--k", "1", "--held-out"]);
    util::assert_clean_failure(&seen, "--held-out");
    assert!(!out.join("fig6.jpg").exists());

    let o = run(&["--materials", "m0,m1", "--k", "2,1"]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let csv5 = std::fs::read_to_string(out.join("fig5.csv")).unwrap();
    assert_eq!(csv5.lines().count(), 5, "{csv5}");
    assert!(csv5.starts_with("material,pc1,pc2,labelled,z0,z1\n"), "{csv5}");
    let csv6 = std::fs::read_to_string(out.join("fig6.csv")).unwrap();
    let mut lines = csv6.lines();
    assert_eq!(
        lines.next(),
        Some("material,render_noise,deepbrdf_2,pca_1,pca_2,ipca_1,ipca_2"),
        "{csv6}"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2, "{csv6}");
    for line in rows {
        let v: Vec<f64> = line.split(',').skip(1).map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{line}");
    }
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.contains("In-sample") && summary.contains("| m1 |"), "{summary}");
    assert!(std::fs::read(out.join("fig5.png")).unwrap().starts_with(b"\x89PNG"));
    assert!(std::fs::read(out.join("fig6.jpg")).unwrap().starts_with(b"\xff\xd8\xff"));
}

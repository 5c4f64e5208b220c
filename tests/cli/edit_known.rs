//! `train --corpus [--held-passes N]`, `train-regressor --corpus` and `edit-known` end to end with a tiny model on
//! four synthetic materials and a few corpus materials: the corpus materials join the training
//! set, and every known-answer edit is scored for each of the nine methods (Sun et al. 2018's
//! split fitted to the four), the analytic edit ending nearer the answer than the unedited
//! material.
use crate::util::{self, s};

#[test]
fn corpus_training_and_known_answer_edits() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 4);
    let ok = util::runner(dir.path());
    let corpus = dir.path().join("corpus");
    ok(&["corpus", "--count", "40", "--seed", "5", "--out", &s(&corpus)]);
    let file = s(&corpus.join("corpus.jsonl"));
    let config = util::tiny_config(dir.path());
    let run = dir.path().join("run");
    let err = util::stderr(&ok(&[
        "train",
        "--config",
        &s(&config),
        "--data",
        &s(&data),
        "--corpus",
        &file,
        "--corpus-count",
        "2",
        "--held-passes",
        "2",
        "--out",
        &s(&run),
    ]));
    assert!(err.contains("(6 BRDFs)") && err.contains("corpus(2 of corpus.jsonl)"), "{err}");
    let saved = std::fs::read_to_string(run.join("train_config.json")).unwrap();
    assert!(saved.contains("\"held_passes\": 2"), "{saved}");
    let model = s(&run);
    ok(&[
        "train-regressor",
        "--model",
        &model,
        "--data",
        &s(&data),
        "--corpus",
        &file,
        "--corpus-count",
        "2",
        "--epochs",
        "20",
        "--ipca",
    ]);
    let out = dir.path().join("known");
    let printed = util::stdout(&ok(&[
        "edit-known",
        "--model",
        &model,
        "--data",
        &s(&data),
        "--count",
        "2",
        "--seed",
        "7",
        "--out",
        &s(&out),
        "--methods",
        "analytic,stretch,parts,deepbrdf-residual,deepbrdf-paper,deepbrdf-nearest,ipca-residual,deepbrdf-transfer,deepbrdf-transfer-paper,ipca-transfer,sun2018-stretch",
    ]));
    assert!(printed.contains("| analytic | **all** |"), "{printed}");
    let csv = std::fs::read_to_string(out.join("known.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let methods = [
        "analytic",
        "stretch",
        "parts",
        "DeepBRDF residual",
        "DeepBRDF paper",
        "DeepBRDF nearest",
        "IPCA residual",
        "DeepBRDF transfer",
        "DeepBRDF transfer (paper)",
        "IPCA transfer",
        "stretch on Sun2018's split",
    ];
    assert!(!rows.is_empty() && rows.len() % methods.len() == 0, "{csv}");
    for method in methods {
        let count = rows.iter().filter(|r| r[2] == method).count();
        assert_eq!(count, rows.len() / methods.len(), "{csv}");
    }
    // The analytic edit of an analytic material moves towards the answer.
    assert!(rows.iter().filter(|r| r[2] == "analytic").all(|r| r[7] == "false"), "{csv}");
    assert!(std::fs::read_to_string(out.join("results.md")).unwrap().contains("--seed 7"));
    // A missing corpus file and a zero pass count are clean errors.
    let missing = s(&dir.path().join("none.jsonl"));
    let (config_s, data_s) = (s(&config), s(&data));
    let refused = |extra: &[&str], needle: &str| {
        let mut args = vec!["train", "--config", &config_s, "--data", &data_s, "--out", "x"];
        args.extend_from_slice(extra);
        util::assert_clean_failure(&util::run_in(dir.path(), &args), needle);
    };
    refused(&["--corpus", &missing], "none.jsonl");
    refused(&["--held-passes", "0"], "passes over the held samples");
}

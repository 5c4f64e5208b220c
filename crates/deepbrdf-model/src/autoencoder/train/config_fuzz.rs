//! Fuzzing of the training-configuration reader ([`TrainConfig::parse`], what `train --config`,
//! `sweep-k --train-config` and `bench model --config` read): mutants of the two presets' JSON
//! ([`deepbrdf_data::testing::mutate`]) are refused with an error or read, never a panic, and
//! what is read passes the size checks that keep a network from being absurdly large.
//!
//! `DEEPBRDF_FUZZ_INPUTS=1000000 cargo test --release -p deepbrdf-model mutated_training --
//! --nocapture` runs a million inputs.

use std::path::Path;

use burn::config::config_to_json;
use deepbrdf_data::testing::mutate::{fuzz, inputs, Focus};

use super::TrainConfig;

#[test]
fn mutated_training_configurations_are_refused_or_read_never_a_panic() {
    let corpus: Vec<Vec<u8>> = [TrainConfig::slice(10), TrainConfig::paper(5)]
        .iter()
        .map(|c| config_to_json(c).into_bytes())
        .collect();
    let origin = Path::new("train_config.json");
    for bytes in &corpus {
        TrainConfig::parse(origin, bytes).unwrap();
    }
    let focus = Focus { header: 4096, header_share: 1.0 };
    let mut read = Vec::new();
    let report = fuzz(&corpus, 31, inputs(3_000), focus, |b| {
        TrainConfig::parse(origin, b).map(|c| read.push(c.model.latent))
    });
    eprintln!("train_config.json: {report:?}");
    assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
    assert!(report.rejected > 0 && report.accepted > 0, "{report:?}");
    assert!(read.iter().all(|&k| (1..=4096).contains(&k)), "a latent size out of range was read");
}

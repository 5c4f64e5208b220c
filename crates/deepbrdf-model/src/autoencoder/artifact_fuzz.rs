//! Fuzzing of the model artifact's readers: the manifest parser with its configuration checks
//! and the burnpack weights loader, each fed mutants of a real saved part
//! ([`deepbrdf_data::testing::mutate`]). The weights reader is called directly, past the
//! manifest's checksums that would refuse every mutant before it, as if a damaged part had
//! been sealed by a matching manifest.
//!
//! `DEEPBRDF_FUZZ_INPUTS=1000000 cargo test --release -p deepbrdf-model mutated_model_parts --
//! --nocapture` runs a million inputs per reader; the test suite runs a few thousand.

use std::path::Path;

use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::merl::VALUES;
use deepbrdf_data::testing::mutate::{fuzz, inputs, Focus, Report};

use super::tests::{provenance, tiny};
use super::*;
use crate::device::DeviceKind;
use std::fs;

fn check(name: &str, report: &Report, started: std::time::Instant) {
    eprintln!("{name}: {report:?} in {:.1} s", started.elapsed().as_secs_f64());
    assert!(report.panics.is_empty(), "{name} panicked: {:?}", report.panics);
    assert!(report.rejected > 0, "{name}: no mutant was refused: {report:?}");
}

#[test]
fn mutated_model_parts_are_refused_or_read_never_a_panic() {
    let device = DeviceKind::default_kind().unwrap().device().unwrap();
    // The tests' tiny network without its mean offset (a layout-sized parameter), so its
    // weights are a few kilobytes and a mutant is cheap.
    let mut config = tiny();
    if let crate::autoencoder::Architecture::Convolutional(layers) = &mut config.architecture {
        layers.mean_offset = false;
    }
    let network = config.init_seeded(3, &device).unwrap();
    let reference = MedianReference::from_values(vec![0.25; VALUES]).unwrap();
    let artifact = ModelArtifact::new(config, provenance(), &network, reference).unwrap();
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("model");
    artifact.save(&dir).unwrap();
    let manifest = fs::read(dir.join(MANIFEST_FILE)).unwrap();
    // The record inside the packed file (the packing's own reader is fuzzed in deepbrdf-data).
    let weights = crate::artifact::files::read_weights(&dir.join(WEIGHTS_FILE), 1 << 30).unwrap();
    let n = inputs(2_000);

    // The manifest: JSON, format and version, the configuration and its size checks. The
    // unchanged file parses (the test's control).
    let origin = Path::new("model.json");
    parse(origin, &manifest).unwrap();
    let focus = Focus { header: manifest.len(), header_share: 1.0 };
    let t = std::time::Instant::now();
    let report = fuzz(&[manifest], 21, n, focus, |b| parse(origin, b));
    check("model.json", &report, t);

    // The weights (burnpack): loaded into the network the configuration builds.
    load_weights(network.clone(), weights.clone()).unwrap();
    let focus = Focus { header: 256, header_share: 0.5 };
    // The crashes fuzzing found (a tensor's dtype field turned into an integer type: Burn
    // panicked inside its loader), kept as regression inputs.
    for (name, bytes) in [
        ("i32", &include_bytes!("../testdata/fuzz/weights-dtype-i32.bpk")[..]),
        ("u32", &include_bytes!("../testdata/fuzz/weights-dtype-u32.bpk")[..]),
    ] {
        let err = load_weights(network.clone(), bytes.to_vec()).expect_err(name).to_string();
        assert!(err.contains("not as floats"), "{name}: {err}");
    }
    let t = std::time::Instant::now();
    let report = fuzz(&[weights], 22, n, focus, |b| load_weights(network.clone(), b.to_vec()));
    check("weights.bpk", &report, t);
}

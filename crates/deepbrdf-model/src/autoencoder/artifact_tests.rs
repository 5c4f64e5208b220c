//! Tests of the model artifact: saving, loading, mismatched parts, edited manifests, and the
//! refusal of retired formats.

use super::*;
use crate::device::DeviceKind;
use deepbrdf_data::merl::VALUES;
use std::fs;

pub(super) fn tiny() -> AutoencoderConfig {
    let layers = crate::autoencoder::ConvolutionalConfig::new()
        .with_projection(Some(1))
        .with_encoder_channels([1, 1, 1])
        .with_residual_blocks(1)
        .with_decoder_channels([1, 1])
        .with_mean_offset(true);
    AutoencoderConfig::convolutional(2, layers)
}

pub(super) fn provenance() -> Provenance {
    Provenance {
        data_label: "synthetic".into(),
        materials: vec!["a".into(), "b".into()],
        data_fingerprint: "00".into(),
        train_config: serde_json::json!({"seed": 1}),
        seed: 1,
        epochs: 3,
        final_loss: 0.593_586_030_006_408_7,
        final_mse: 0.25,
        train_seconds: 339.123_456_789,
        device: "test".into(),
    }
}

fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
}

#[test]
fn saved_artifacts_load_and_mismatched_parts_are_detected() {
    let device = DeviceKind::default_kind().unwrap().device().unwrap();
    let model_a = tiny().init_seeded(1, &device).unwrap();
    let model_b = tiny().init_seeded(2, &device).unwrap();
    let ref_a = MedianReference::from_values(vec![0.25; VALUES]).unwrap();
    let ref_b = MedianReference::from_values(vec![0.5; VALUES]).unwrap();
    let a = ModelArtifact::new(tiny(), provenance(), &model_a, ref_a).unwrap();
    let b = ModelArtifact::new(tiny(), provenance(), &model_b, ref_b).unwrap();
    assert_ne!(a.id(), b.id());

    let root = tempfile::tempdir().unwrap();
    let (dir_a, dir_b) = (root.path().join("run").join(MODEL_DIR), root.path().join("b"));
    fs::create_dir_all(root.path().join("run")).unwrap();
    a.save(&dir_a).unwrap();
    a.save(&dir_a).unwrap(); // replacing an artifact is allowed
    b.save(&dir_b).unwrap();
    let back = ModelArtifact::load(&dir_a).unwrap();
    assert_eq!(back.id(), a.id());
    assert!((back.provenance().final_loss - provenance().final_loss).abs() < 1e-15);
    // A training directory resolves to its model/.
    assert_eq!(ModelArtifact::load(&root.path().join("run")).unwrap().id(), a.id());
    // The loaded weights are the saved ones.
    let z = Tensor::<2>::from_floats([[0.3, -0.7]], &device);
    let expected: Vec<f32> = model_a.decode(z.clone()).into_data().try_into_vec().unwrap();
    let got: Vec<f32> = back.model(&device).unwrap().decode(z).into_data().try_into_vec().unwrap();
    assert_eq!(expected, got);

    for (file, what) in [(WEIGHTS_FILE, "weights"), (REFERENCE_FILE, "median reference")] {
        let mixed = root.path().join(format!("mixed-{what}"));
        copy_dir(&dir_a, &mixed);
        fs::copy(dir_b.join(file), mixed.join(file)).unwrap();
        let err = ModelArtifact::load(&mixed).unwrap_err().to_string();
        assert!(err.contains(file) && err.contains("not belong"), "{err}");
    }
    let edited = root.path().join("edited");
    copy_dir(&dir_a, &edited);
    let text = fs::read_to_string(edited.join(MANIFEST_FILE)).unwrap();
    fs::write(
        edited.join(MANIFEST_FILE),
        text.replace("\"final_mse\": 0.25", "\"final_mse\": 0.01"),
    )
    .unwrap();
    let err = ModelArtifact::load(&edited).unwrap_err().to_string();
    assert!(err.contains("edited"), "{err}");
    fs::write(edited.join(MANIFEST_FILE), "{ not json").unwrap();
    assert!(ModelArtifact::load(&edited).unwrap_err().to_string().contains("model.json"));

    // Never replaces a directory that is not a model, nor loads from one.
    let user = root.path().join("user");
    fs::create_dir_all(&user).unwrap();
    fs::write(user.join("notes.txt"), "mine").unwrap();
    assert!(a.save(&user).is_err());
    assert_eq!(fs::read_to_string(user.join("notes.txt")).unwrap(), "mine");
    assert!(ModelArtifact::load(&user).is_err());
    assert!(ModelArtifact::load(&root.path().join("missing")).is_err());
}

#[test]
fn a_model_saved_in_the_earlier_form_loads_with_the_same_id_and_weights() {
    // Earlier versions wrote weights.bpk as a plain burnpack record and the median reference
    // as one zstd frame (or plain); this version writes both packed. Every form loads to the
    // same id, reference and network.
    let device = DeviceKind::default_kind().unwrap().device().unwrap();
    let model = tiny().init_seeded(4, &device).unwrap();
    let values = (0..VALUES).map(|i| 0.01 + (i % 313) as f32 * 0.003).collect();
    let reference = MedianReference::from_values(values).unwrap();
    let artifact = ModelArtifact::new(tiny(), provenance(), &model, reference.clone()).unwrap();
    let root = tempfile::tempdir().unwrap();
    let packed = root.path().join("packed");
    artifact.save(&packed).unwrap();
    for file in [WEIGHTS_FILE, REFERENCE_FILE] {
        let stored = fs::read(packed.join(file)).unwrap();
        assert!(deepbrdf_data::packed::is_packed(&stored), "{file}");
    }
    let plain_reference = root.path().join("plain.bin");
    reference.save(&plain_reference).unwrap();
    let plain_reference = fs::read(&plain_reference).unwrap();
    let zstd_reference = zstd::bulk::compress(&plain_reference, 3).unwrap();
    let record = crate::artifact::files::read_weights(&packed.join(WEIGHTS_FILE), 1 << 30).unwrap();
    let z = Tensor::<2>::from_floats([[0.4, -0.2]], &device);
    let expected: Vec<f32> = model.decode(z.clone()).into_data().try_into_vec().unwrap();
    for (name, reference_bytes) in [("zstd", &zstd_reference), ("plain", &plain_reference)] {
        let old = root.path().join(name);
        copy_dir(&packed, &old);
        fs::write(old.join(WEIGHTS_FILE), &record).unwrap();
        fs::write(old.join(REFERENCE_FILE), reference_bytes).unwrap();
        let back = ModelArtifact::load(&old).unwrap();
        assert_eq!(back.id(), artifact.id(), "{name}");
        assert_eq!(back.reference(), &reference, "{name}");
        let got: Vec<f32> =
            back.model(&device).unwrap().decode(z.clone()).into_data().try_into_vec().unwrap();
        assert_eq!(got, expected, "{name}");
    }
}

#[test]
fn a_model_of_a_retired_format_is_refused_with_what_to_do() {
    // Minimal manifests of the kinds earlier versions wrote: the `cpu` preset's spectral
    // network with its compact basis, and the flat configuration format.
    let device = DeviceKind::default_kind().unwrap().device().unwrap();
    let model = tiny().init_seeded(1, &device).unwrap();
    let reference = MedianReference::from_values(vec![0.25; VALUES]).unwrap();
    let artifact = ModelArtifact::new(tiny(), provenance(), &model, reference).unwrap();
    let root = tempfile::tempdir().unwrap();
    let spectral = serde_json::json!({"latent": 10, "negative_slope": 0.01,
        "architecture": {"spectral": {"directions": 96, "hidden": 256, "he_init": true}}});
    let flat = serde_json::json!({"latent": 2, "projection": 1, "mean_offset": true});
    let part = serde_json::json!({"file": "basis.f16", "bytes": 8, "sha256": "00"});
    for (name, config, basis) in [("cpu", spectral, Some(part)), ("flat", flat, None)] {
        let run = root.path().join(name);
        let dir = run.join(MODEL_DIR);
        fs::create_dir_all(&run).unwrap();
        artifact.save(&dir).unwrap();
        let path = dir.join(MANIFEST_FILE);
        let mut manifest: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
        manifest["config"] = config;
        if let Some(basis) = basis {
            manifest["basis"] = basis;
        }
        fs::write(&path, manifest.to_string()).unwrap();
        for given in [&run, &dir] {
            let err = ModelArtifact::load(given).unwrap_err().to_string();
            assert!(err.starts_with(&dir.display().to_string()), "{err}");
            assert!(err.contains("retired format"), "{err}");
            assert!(err.contains("--preset slice") && err.contains("commit"), "{err}");
        }
    }
}

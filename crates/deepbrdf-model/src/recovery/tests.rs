//! A tiny recovery CNN (8x8 inputs) trained for a few epochs through the loop, saved, loaded
//! and refused for another model.

use super::artifact::{RECOVERY_MANIFEST, RECOVERY_WEIGHTS};
use super::*;
use crate::train::{adam, LoopConfig, Session};
use deepbrdf_data::Silent;

fn tiny() -> RecoveryConfig {
    RecoveryConfig::new(8, [2, 3, 3], [3, 3, 3], [1, 1, 1], 8, 2)
}

/// 12 images whose two targets are their mean red and the brightness of their left half.
fn data() -> RecoveryData {
    let s = 8;
    let mut images = Vec::new();
    let mut targets = Vec::new();
    for i in 0..12 {
        let (r, g) = ((i % 4) as f32 / 4.0, (i / 4) as f32 / 3.0);
        for c in 0..3 {
            for _y in 0..s {
                for x in 0..s {
                    images.push(if c == 0 {
                        r
                    } else if x < s / 2 {
                        g
                    } else {
                        0.1
                    });
                }
            }
        }
        targets.extend([r * 10.0, g - 5.0]);
    }
    RecoveryData { side: s, outputs: 2, images, targets }
}

fn settings() -> LoopConfig {
    LoopConfig::new(adam())
        .with_learning_rate(1e-2)
        .with_epochs(30)
        .with_batch_size(4)
        .with_seed(2)
        .with_checkpoint_seconds(0.0)
}

fn provenance() -> RecoveryProvenance {
    RecoveryProvenance {
        set: "set".into(),
        set_digest: "00".into(),
        images: 12,
        materials: vec!["a".into()],
        data_fingerprint: data().fingerprint(),
        train_config: serde_json::json!({"preset": "test"}),
        epochs: 30,
        final_loss: 0.5,
        train_seconds: 1.0,
        device: "test".into(),
    }
}

#[test]
fn a_tiny_recovery_cnn_learns_saves_and_names_its_model() {
    let device = crate::DeviceKind::default_kind().unwrap().device().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let session = Session::new(dir.path(), false, &Silent, "recovery");
    let trained =
        train_recovery(&tiny(), &settings(), &data(), &session, &device, &Silent).unwrap();
    let (first, last) = (trained.log[0].loss, trained.log.last().unwrap().loss);
    assert!(last < 0.5 * first, "L1 {first} -> {last}");
    // Standardisation: the mean of the targets (10 * 3/8 and 1/3 - 5).
    assert!((trained.mean[0] - 3.75).abs() < 1e-5 && (trained.mean[1] + 14.0 / 3.0).abs() < 1e-5);

    let target = RecoveryTarget::Latent { model_id: "abc".into(), k: 2 };
    let artifact = RecoveryArtifact::new(tiny(), target, &trained, provenance()).unwrap();
    let out = dir.path().join("recovery");
    artifact.save(&out).unwrap();
    let back = RecoveryArtifact::load(dir.path()).unwrap(); // resolves recovery/
    assert_eq!(back.id(), artifact.id());
    back.check_model("abc").unwrap();
    let e = back.check_model("xyz").unwrap_err().to_string();
    assert!(e.contains("abc") && e.contains("xyz"), "{e}");
    // The loaded network predicts what the trained one does, in target units.
    let d = data();
    let rows = back.predictor(&device).unwrap().predict(&d.images).unwrap();
    let again = artifact.predictor(&device).unwrap().predict(&d.images).unwrap();
    assert_eq!(rows, again);
    let mean_error: f32 = rows
        .iter()
        .zip(d.targets.chunks(2))
        .map(|(p, t)| (p[0] - t[0]).abs() + (p[1] - t[1]).abs())
        .sum::<f32>()
        / 24.0;
    assert!(mean_error < 1.5, "mean L1 {mean_error} (targets spread over 10)");

    // Tampering is detected; a user's folder is not replaced.
    let text = std::fs::read_to_string(out.join(RECOVERY_MANIFEST)).unwrap();
    std::fs::write(out.join(RECOVERY_MANIFEST), text.replace("\"abc\"", "\"xyz\"")).unwrap();
    assert!(RecoveryArtifact::load(&out).unwrap_err().to_string().contains("edited"));
    std::fs::write(out.join(RECOVERY_WEIGHTS), b"junk").unwrap();
    assert!(RecoveryArtifact::load(&out).unwrap_err().to_string().contains("not belong"));
    let user = dir.path().join("mine");
    std::fs::create_dir_all(&user).unwrap();
    assert!(artifact.save(&user).is_err());
    // Outputs must match the target.
    let bad = RecoveryArtifact::new(tiny(), RecoveryTarget::Attributes, &trained, provenance());
    assert!(bad.is_err());
}

#[test]
fn the_presets_fit_their_input_sides() {
    for (preset, side) in [(RecoveryPreset::Small, 64), (RecoveryPreset::Paper, 256)] {
        let c = preset.network(10);
        c.validate().unwrap();
        assert_eq!(c.input_side, side);
        assert!(c.flat_features() > 0);
        assert_eq!(preset.name().parse::<RecoveryPreset>().unwrap(), preset);
    }
    // The earlier name of `small` still parses; others are refused naming the presets.
    assert_eq!(" CPU".parse::<RecoveryPreset>().unwrap(), RecoveryPreset::Small);
    assert!("tiny".parse::<RecoveryPreset>().unwrap_err().contains("small or paper"));
    assert_eq!(RecoveryPreset::Paper.network(10).sides(), [128, 64, 64, 32, 16]);
    assert_eq!(RecoveryPreset::Paper.loop_config().batch_size, 64);
    assert!(RecoveryConfig::new(8, [1, 1, 1], [4, 3, 3], [1, 1, 1], 4, 2).validate().is_err());
}

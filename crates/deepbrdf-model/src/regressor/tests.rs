//! The regressor on synthetic pairs: it learns through the shared loop, saves and loads the same
//! predictions, is deterministic, and refuses other models, damaged files and bad attributes.

use super::*;
use crate::train::Session;
use deepbrdf_data::Silent;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` materials with seeded attributes and k = 3 smooth targets of them.
fn pairs(n: usize) -> RegressorData {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let attributes: Vec<[f64; 7]> = (0..n)
        .map(|_| {
            let mut a: [f64; 7] = std::array::from_fn(|_| rng.random_range(0.0..1.0));
            a[6] = 10f64.powf(rng.random_range(-2.5..0.0));
            a
        })
        .collect();
    let targets = attributes
        .iter()
        .map(|a| {
            let d = a[0] + a[1] + a[2];
            vec![(2.0 * d - 1.0) as f32, (5.0 + a[6].ln()) as f32, (3.0 * a[3] - a[5]) as f32]
        })
        .collect();
    RegressorData {
        label: "synthetic".into(),
        names: (0..n).map(|i| format!("m{i}")).collect(),
        attributes,
        targets,
    }
}

fn config(epochs: usize) -> RegressorConfig {
    let mut c = RegressorConfig { hidden: 32, ..RegressorConfig::default() };
    c.training =
        c.training.with_epochs(epochs).with_learning_rate(3e-3).with_checkpoint_seconds(0.0);
    c
}

fn target(owner: &str) -> Target {
    Target { kind: TargetKind::DeepBrdf, owner_id: owner.into(), k: 3 }
}

fn device() -> Device {
    crate::DeviceKind::default_kind().unwrap().device().unwrap()
}

use burn::prelude::Device;

#[test]
fn a_regressor_learns_saves_and_refuses_another_model() {
    let data = pairs(40);
    let dir = tempfile::tempdir().unwrap();
    let session = Session::new(dir.path(), false, &Silent, "regressor");
    let r = train_regressor(&data, &config(60), target("model-a"), &session, &device()).unwrap();
    let err = r.provenance().train_relative_error;
    assert!(err < 0.1, "training relative error {err}");
    assert!(r.provenance().final_loss < 0.15, "{:?}", r.provenance());

    let path = dir.path().join(TargetKind::DeepBrdf.file_name());
    r.save(&path).unwrap();
    let back =
        Regressor::load_for(dir.path(), TargetKind::DeepBrdf, "model-a", 3, &device()).unwrap();
    assert_eq!(back.id(), r.id());
    assert_eq!(back.predict(&data.attributes[3]).unwrap(), r.predict(&data.attributes[3]).unwrap());

    // Another model, another k, another kind: refused naming both.
    let e = Regressor::load_for(&path, TargetKind::DeepBrdf, "model-b", 3, &device()).unwrap_err();
    let e = e.to_string();
    assert!(e.contains("model-a") && e.contains("model-b") && e.contains("train-regressor"), "{e}");
    assert!(Regressor::load_for(&path, TargetKind::DeepBrdf, "model-a", 4, &device()).is_err());
    let e = Regressor::load_for(dir.path(), TargetKind::Ipca, "model-a", 3, &device()).unwrap_err();
    assert!(e.to_string().contains("ipca.regressor"), "{e}");

    // Bad attributes.
    let mut a = data.attributes[0];
    a[6] = -0.1;
    assert!(r.predict(&a).unwrap_err().to_string().contains("roughness"));
    a[6] = 0.1;
    a[0] = f64::NAN;
    assert!(r.predict(&a).is_err());

    // A damaged file names itself; a foreign file is not replaced.
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[200] ^= 1;
    let damaged = dir.path().join("damaged.regressor");
    std::fs::write(&damaged, &bytes).unwrap();
    let e = Regressor::load(&damaged, &device()).unwrap_err().to_string();
    assert!(e.contains("damaged.regressor"), "{e}");
    let user = dir.path().join("notes.txt");
    std::fs::write(&user, "mine").unwrap();
    assert!(r.save(&user).is_err());
    assert_eq!(std::fs::read_to_string(&user).unwrap(), "mine");

    // The same seed gives the same network in another directory (the ids differ: they cover
    // the training seconds).
    let other = tempfile::tempdir().unwrap();
    let session = Session::new(other.path(), false, &Silent, "regressor");
    let again =
        train_regressor(&data, &config(60), target("model-a"), &session, &device()).unwrap();
    for a in &data.attributes {
        assert_eq!(again.predict(a).unwrap(), r.predict(a).unwrap());
    }
}

#[test]
fn bad_training_pairs_are_refused() {
    let mut data = pairs(4);
    data.targets[1].pop();
    let dir = tempfile::tempdir().unwrap();
    let session = Session::new(dir.path(), false, &Silent, "regressor");
    let e = train_regressor(&data, &config(2), target("m"), &session, &device()).unwrap_err();
    assert!(e.to_string().contains("k = 3"), "{e}");
    let mut data = pairs(4);
    data.attributes[2][6] = 0.0;
    let e = train_regressor(&data, &config(2), target("m"), &session, &device()).unwrap_err();
    assert!(e.to_string().contains("roughness"), "{e}");
}

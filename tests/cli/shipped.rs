//! The model shipped in the repository (`models/default`) works right after a clone: `encode`,
//! `decode` and `edit` without `--model` use it, with its editing regressor, and `recover`
//! uses its recovery network.
use crate::util;
use deepbrdf_data::cache::Cache;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::merl::read_merl;
use deepbrdf_eval::editing::lobe::Lobe;
use std::path::Path;

use crate::util::s;

#[test]
fn the_shipped_model_encodes_decodes_edits_and_recovers_without_model_options() {
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 1);
    let m0 = s(&data.join("m0.binary"));
    let ok = util::runner(dir.path());
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/default/model/model.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let id = manifest["id"].as_str().unwrap().to_string();

    let latent = dir.path().join("m0.json");
    ok(&["encode", &m0, "-o", &s(&latent)]);
    let text = std::fs::read_to_string(&latent).unwrap();
    assert!(text.contains(&id), "the latent names the shipped model {id}: {text}");
    let decoded = dir.path().join("d.binary");
    ok(&["decode", &s(&latent), "-o", &s(&decoded)]);
    assert_eq!(read_merl(&decoded).unwrap().mask(), util::material(0).mask());

    let edited = dir.path().join("e.binary");
    let out = ok(&["edit", &m0, "--diffuse-scale", "0.5", "--mode", "residual", "-o", &s(&edited)]);
    assert!(util::stdout(&out).contains(&id), "{}", util::stdout(&out));
    assert!(read_merl(&edited).is_ok());
    // Without --mode: the parts edit, which needs no network.
    let out = ok(&["edit", &m0, "--roughness-scale", "0.5", "-o", &s(&edited), "--force"]);
    assert!(util::stdout(&out).contains("no network, parts edit"), "{}", util::stdout(&out));
    assert!(read_merl(&edited).is_ok());

    // A photo of the material (a render over black), recovered with the shipped network.
    let photo = dir.path().join("photo.png");
    ok(&["render", &m0, "-o", &s(&photo), "--size", "64", "--spp", "4"]);
    let recovered = dir.path().join("r.binary");
    let compare = dir.path().join("c.png");
    let out = ok(&["recover", &s(&photo), "-o", &s(&recovered), "--render", &s(&compare)]);
    assert_eq!(read_merl(&recovered).unwrap().mask(), util::material(0).mask());
    assert!(compare.is_file(), "{}", util::stdout(&out));
}

#[test]
fn the_shipped_model_halves_the_diffuse_floor_when_asked_to() {
    // An edit the shipped model was trained to do, on a material it saw: diffuse albedo x0.5
    // must lower the diffuse floor (the median luminance away from the highlight,
    // `deepbrdf_eval::editing::lobe`) and leave the highlight's peak above it.
    let dir = tempfile::tempdir().unwrap();
    let material = "red-plastic";
    let edited = dir.path().join("e.binary");
    let out = util::run_in(
        dir.path(),
        &["edit", material, "--diffuse-scale", "0.5", "--mode", "residual", "-o", &s(&edited)],
    );
    assert!(out.status.success(), "{}", util::stderr(&out));
    let (_, original) = load_material(material, &Cache::disabled()).unwrap();
    let before = Lobe::of(&original).unwrap();
    let after = Lobe::of(&read_merl(&edited).unwrap()).unwrap();
    let ratio = after.floor / before.floor;
    assert!(
        (0.2..0.8).contains(&ratio),
        "diffuse x0.5: floor {:.4e} -> {:.4e} ({ratio:.3}x)",
        before.floor,
        after.floor
    );
    assert!(after.peak > 0.0, "the highlight is gone: {after:?}");
}

/// The mapped-space MSE `reconstruct` prints ("...: k = K, mapped-space MSE E; wrote ...").
fn reconstruction_error(out: &std::process::Output) -> f64 {
    let text = util::stdout(out);
    let tail = text.split("mapped-space MSE ").nth(1).unwrap_or_else(|| panic!("{text}"));
    tail.split(|c: char| c == ';' || c.is_whitespace()).next().unwrap().parse().unwrap()
}

#[test]
fn refining_the_encoding_never_raises_the_error_and_lowers_it_on_average() {
    // Synthetic materials no model saw; --refine 0 is the encoder's latent as it is. A
    // refinement step is kept only when it lowers the mapped error (the error `reconstruct`
    // prints), so no material may get worse, and on materials outside the training set the
    // encoder leaves something to gain.
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 4);
    let error = |material: &str, refine: &str| {
        let args = ["reconstruct", material, "-o", "r.binary", "--refine", refine];
        let out = util::run_in(dir.path(), &args);
        assert!(out.status.success(), "{args:?}: {}", util::stderr(&out));
        reconstruction_error(&out)
    };
    let (mut encoder_sum, mut refined_sum) = (0.0, 0.0);
    for i in 0..4 {
        let m = s(&data.join(format!("m{i}.binary")));
        let (encoder, refined) = (error(&m, "0"), error(&m, "20"));
        assert!(refined.is_finite() && encoder.is_finite(), "m{i}");
        // The printed error has five significant digits; allow their rounding.
        assert!(refined <= encoder * (1.0 + 1e-4), "m{i}: refined {refined:e} vs {encoder:e}");
        encoder_sum += encoder;
        refined_sum += refined;
    }
    assert!(refined_sum < encoder_sum, "refined {refined_sum:e} vs the encoder's {encoder_sum:e}");
}

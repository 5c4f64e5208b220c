//! Network configurations this version no longer builds, recognised so that a model directory
//! or checkpoint holding one is refused with what it is and what to do instead of a parse
//! error: the spectral network of the retired `cpu` preset (`{"architecture": {"spectral":
//! ...}}`) and the flat configuration format of earlier versions (a `convolutional` flag,
//! `spectral_basis` and the convolution widths side by side, no `architecture`).
//! CHANGELOG.md says why they were retired.

/// The last commit of deepbrdf that reads both retired formats.
pub(crate) const LAST_COMMIT_READING_RETIRED: &str = "05ea8e2";

/// What retired format the network configuration `value` is in, if it is in one.
pub(crate) fn retired_network(value: &serde_json::Value) -> Option<&'static str> {
    let object = value.as_object()?;
    match object.get("architecture") {
        Some(architecture) => architecture
            .as_object()
            .is_some_and(|a| a.contains_key("spectral"))
            .then_some("the spectral network of the retired `cpu` preset"),
        None => ["convolutional", "spectral_basis", "encoder_channels", "projection"]
            .iter()
            .any(|k| object.contains_key(*k))
            .then_some("the flat network configuration of earlier versions"),
    }
}

/// The refusal of a configuration in the retired format `what`, with what to do.
pub(crate) fn message(what: &str) -> String {
    format!(
        "a model of a retired format ({what}), which this version of deepbrdf no longer \
         reads; retrain it with `experiments train --preset slice` (the shipped model's \
         preset), or use deepbrdf at commit {LAST_COMMIT_READING_RETIRED} or earlier"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retired_configurations_are_recognised_and_current_ones_are_not() {
        let spectral = serde_json::json!({"latent": 10, "negative_slope": 0.01,
            "architecture": {"spectral": {"directions": 96, "hidden": 256, "he_init": true}}});
        let flat = serde_json::json!({"latent": 10, "convolutional": false,
            "spectral_basis": 96, "mean_offset": true});
        let flat_table1 = serde_json::json!({"latent": 7, "projection": null});
        assert!(retired_network(&spectral).unwrap().contains("`cpu`"));
        assert!(retired_network(&flat).unwrap().contains("flat"));
        assert!(retired_network(&flat_table1).is_some());
        for current in [
            crate::AutoencoderConfig::paper(5).to_string(),
            crate::AutoencoderConfig::slice(10).to_string(),
        ] {
            let value: serde_json::Value = serde_json::from_str(&current).unwrap();
            assert_eq!(retired_network(&value), None, "{current}");
        }
        let err = message("x");
        assert!(err.contains("--preset slice") && err.contains(LAST_COMMIT_READING_RETIRED));
    }
}

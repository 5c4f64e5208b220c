//! The targets of the recovery networks (§5.2): DeepBRDF's latent (eq. 2) of a material, or
//! its 7 Lambertian + GGX attributes (§5.1) with the roughness as its logarithm, the scale it
//! varies on; and the way back from 7 predicted outputs to attributes.
use crate::attributes::{fit, Attributes, FitConfig, MAX_ROUGHNESS, MIN_ROUGHNESS};
use crate::deep::NAME;
use crate::error::{EvalError, Result};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_model::DeepBrdf;
use std::collections::BTreeMap;

/// Outputs of an attributes network: diffuse RGB, specular RGB, ln(roughness).
pub const ATTRIBUTE_TARGETS: usize = 7;

/// DeepBRDF's latent of each table.
pub fn latents(
    model: &DeepBrdf,
    tables: &BTreeMap<String, MerlTable>,
) -> Result<BTreeMap<String, Vec<f32>>> {
    tables
        .iter()
        .map(|(n, t)| Ok((n.clone(), model.encode(t).map_err(|e| EvalError::method(NAME, e))?)))
        .collect()
}

/// The 7 targets of attributes: diffuse RGB, specular RGB, ln(roughness).
pub fn attribute_targets(a: &Attributes) -> Vec<f32> {
    let v = a.to_array();
    vec![
        v[0] as f32,
        v[1] as f32,
        v[2] as f32,
        v[3] as f32,
        v[4] as f32,
        v[5] as f32,
        v[6].ln() as f32,
    ]
}

/// Attributes from 7 predicted targets, clamped into their ranges (albedos to [0, 1], the
/// roughness to [`MIN_ROUGHNESS`, `MAX_ROUGHNESS`]).
pub fn attributes_from_targets(targets: &[f32]) -> Result<Attributes> {
    if targets.len() != ATTRIBUTE_TARGETS {
        return Err(EvalError::Invalid(format!(
            "{ATTRIBUTE_TARGETS} attribute outputs expected, got {}",
            targets.len()
        )));
    }
    let t: Vec<f64> = targets.iter().map(|&v| f64::from(v)).collect();
    let albedo = |v: f64| v.clamp(0.0, 1.0);
    let values = [
        albedo(t[0]),
        albedo(t[1]),
        albedo(t[2]),
        albedo(t[3]),
        albedo(t[4]),
        albedo(t[5]),
        t[6].exp().clamp(MIN_ROUGHNESS, MAX_ROUGHNESS),
    ];
    Attributes::from_slice(&values)
}

/// The Lambertian + GGX fit of each table, as targets.
pub fn attribute_fits(
    tables: &BTreeMap<String, MerlTable>,
    progress: &dyn Progress,
) -> Result<BTreeMap<String, Vec<f32>>> {
    progress.start(tables.len() as u64, "fitting attributes");
    let mut out = BTreeMap::new();
    for (name, table) in tables {
        let f = fit(table, &FitConfig::default())
            .map_err(|e| EvalError::Invalid(format!("fitting {name}: {e}")))?;
        out.insert(name.clone(), attribute_targets(&f.attributes));
        progress.advance(1);
    }
    progress.finish();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_round_trip_and_predictions_are_clamped_into_range() {
        let a = Attributes::from_slice(&[0.1, 0.2, 0.3, 0.04, 0.05, 0.06, 0.25]).unwrap();
        let t = attribute_targets(&a);
        assert_eq!(t.len(), ATTRIBUTE_TARGETS);
        // The roughness is learnt as its logarithm.
        assert!((f64::from(t[6]) - 0.25f64.ln()).abs() < 1e-6);
        let back = attributes_from_targets(&t).unwrap().to_array();
        for (b, v) in back.iter().zip(a.to_array()) {
            assert!((b - v).abs() < 1e-6, "{back:?}");
        }
        let wild = attributes_from_targets(&[-1.0, 2.0, 0.5, 0.0, 1.5, -0.1, 3.0]).unwrap();
        assert_eq!(wild.diffuse, [0.0, 1.0, 0.5]);
        assert_eq!(wild.specular, [0.0, 1.0, 0.0]);
        assert_eq!(wild.roughness, MAX_ROUGHNESS);
        let tiny = attributes_from_targets(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -50.0]).unwrap();
        assert_eq!(tiny.roughness, MIN_ROUGHNESS);
        let e = attributes_from_targets(&[0.0; 6]).unwrap_err().to_string();
        assert!(e.contains("7 attribute outputs expected, got 6"), "{e}");
    }
}

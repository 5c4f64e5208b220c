//! The 7-attribute fit as a harness [`Method`]: a 7-number representation of a BRDF beside
//! PCA, IPCA and DeepBRDF at k = 7. Encoding fits the [`Attributes`] ([`fit`]); decoding
//! tabulates the analytic model. Nothing is learnt from the training set, so in-sample and
//! held-out results are the same.

use super::{fit, Attributes, FitConfig};
use crate::error::{EvalError, Result};
use crate::harness::{Codec, Method};
use deepbrdf_data::{MerlTable, Progress};

/// Number of coefficients: diffuse RGB, specular RGB, roughness.
pub const K: usize = 7;

/// The Lambertian + GGX fit as a harness method, named "GGX".
#[derive(Clone, Copy, Debug, Default)]
pub struct AttributeMethod {
    pub config: FitConfig,
}

impl Method for AttributeMethod {
    fn name(&self) -> String {
        "GGX".into()
    }

    fn fit(
        &self,
        _train: &[&MerlTable],
        _names: &[String],
        k: usize,
        _progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        if k != K {
            return Err(EvalError::Invalid(format!(
                "the GGX fit has exactly {K} parameters (diffuse RGB, specular RGB, roughness); \
                 it cannot be evaluated at k = {k}"
            )));
        }
        Ok(Box::new(AttributeCodec { config: self.config }))
    }
}

/// Codec of [`AttributeMethod`].
#[derive(Clone, Copy, Debug)]
pub struct AttributeCodec {
    pub config: FitConfig,
}

impl Codec for AttributeCodec {
    fn name(&self) -> String {
        format!("GGX-{K}")
    }

    fn k(&self) -> usize {
        K
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        let a = fit(table, &self.config)?.attributes;
        Ok(a.to_array().map(|v| v as f32).to_vec())
    }

    fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        let values: Vec<f64> = code.iter().map(|&v| f64::from(v)).collect();
        Ok(Attributes::from_slice(&values)?.table())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::harness::{self, HarnessConfig, Materials, Measure, Mode};
    use deepbrdf_data::Silent;

    #[test]
    fn runs_through_the_harness_at_k_7_only() {
        let truth = [
            Attributes { diffuse: [0.2, 0.3, 0.4], specular: [0.5; 3], roughness: 0.2 },
            Attributes { diffuse: [0.5, 0.1, 0.1], specular: [0.05; 3], roughness: 0.08 },
        ];
        let tables: Vec<MerlTable> = truth.iter().map(Attributes::table).collect();
        let names = vec!["a".to_string(), "b".to_string()];
        let data = Materials { names: &names, tables: &tables, label: "analytic" };
        let method = AttributeMethod::default();
        let config = HarnessConfig {
            ks: vec![K],
            mode: Mode::InSample,
            seed: 0,
            measures: vec![Measure::CosRmse],
            only_fold: None,
        };
        let results = harness::run(&[&method], &config, data, None, &Silent).unwrap();
        // Tables of the model itself are reproduced up to the fit's and f32's precision.
        let err = results.mean("GGX", K, Measure::CosRmse).unwrap();
        assert!(err < 1e-3, "{err}");
        let code = AttributeCodec { config: FitConfig::default() }.encode(&tables[1]).unwrap();
        assert!((code[6] - 0.08).abs() < 0.004, "{code:?}");
        let wrong_k = HarnessConfig { ks: vec![5], ..config };
        let e = harness::run(&[&method], &wrong_k, data, None, &Silent).unwrap_err().to_string();
        assert!(e.contains("k = 5"), "{e}");
        let codec = AttributeCodec { config: FitConfig::default() };
        assert!(codec.decode(&[0.1; 6]).is_err());
        assert!(codec.decode(&[0.1, 0.1, 0.1, 1.5, 0.1, 0.1, 0.1]).is_err());
    }
}

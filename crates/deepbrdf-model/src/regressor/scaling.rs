//! The normalisation of the regressor's inputs and targets (eq. (7)), fitted on the training
//! pairs and recorded in the artifact: the 7 attributes become features (the albedos as they
//! are, the roughness as `ln(alpha)`, since GGX alphas of measured materials span three decades),
//! each standardised to zero mean and unit deviation; the network predicts standardised targets,
//! mapped back as `y = mean + std * output` before the loss, which is taken on the targets
//! themselves.

use serde::{Deserialize, Serialize};

use crate::error::{ModelError, Result};

/// Index of the roughness among the 7 attributes (after diffuse RGB and specular RGB).
const ROUGHNESS: usize = 6;
/// Deviations below this are replaced by 1 (a constant feature or target is only centred).
const MIN_STD: f64 = 1e-8;

/// Per-feature and per-target mean and standard deviation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scaling {
    pub input_mean: Vec<f64>,
    pub input_std: Vec<f64>,
    pub target_mean: Vec<f64>,
    pub target_std: Vec<f64>,
}

/// The 7 features of 7 attributes: the albedos, then `ln(roughness)`.
pub fn features(attributes: &[f64; 7]) -> Result<[f64; 7]> {
    if attributes[ROUGHNESS].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(ModelError::Invalid(format!(
            "the roughness must be positive, got {}",
            attributes[ROUGHNESS]
        )));
    }
    if let Some(i) = attributes.iter().position(|v| !v.is_finite()) {
        return Err(ModelError::Invalid(format!("attribute {i} is not finite")));
    }
    let mut f = *attributes;
    f[ROUGHNESS] = f[ROUGHNESS].ln();
    Ok(f)
}

fn moments(rows: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let n = rows.len() as f64;
    let dim = rows[0].len();
    let mean: Vec<f64> = (0..dim).map(|j| rows.iter().map(|r| r[j]).sum::<f64>() / n).collect();
    let std = (0..dim)
        .map(|j| {
            let var = rows.iter().map(|r| (r[j] - mean[j]).powi(2)).sum::<f64>() / n;
            if var.sqrt() < MIN_STD {
                1.0
            } else {
                var.sqrt()
            }
        })
        .collect();
    (mean, std)
}

impl Scaling {
    /// Fits the scaling to training features (see [`features`]) and targets.
    pub fn fit(features: &[[f64; 7]], targets: &[Vec<f32>]) -> Result<Self> {
        if features.is_empty() || features.len() != targets.len() {
            return Err(ModelError::Invalid(format!(
                "the regressor needs as many attribute rows as targets (and at least one): {} \
                 and {}",
                features.len(),
                targets.len()
            )));
        }
        let k = targets[0].len();
        if k == 0 || targets.iter().any(|t| t.len() != k) {
            return Err(ModelError::Invalid("the targets must all have the same k > 0".into()));
        }
        let inputs: Vec<Vec<f64>> = features.iter().map(|f| f.to_vec()).collect();
        let outputs: Vec<Vec<f64>> =
            targets.iter().map(|t| t.iter().map(|&v| f64::from(v)).collect()).collect();
        if outputs.iter().flatten().chain(inputs.iter().flatten()).any(|v| !v.is_finite()) {
            return Err(ModelError::Invalid("a regressor input or target is not finite".into()));
        }
        let (input_mean, input_std) = moments(&inputs);
        let (target_mean, target_std) = moments(&outputs);
        Ok(Self { input_mean, input_std, target_mean, target_std })
    }

    /// k, the number of targets.
    pub fn k(&self) -> usize {
        self.target_mean.len()
    }

    /// Checks the lengths and values (a loaded artifact's).
    pub fn validate(&self, k: usize) -> Result<()> {
        let ok = self.input_mean.len() == 7
            && self.input_std.len() == 7
            && self.target_mean.len() == k
            && self.target_std.len() == k;
        let values = self.input_mean.iter().chain(&self.target_mean);
        let stds = self.input_std.iter().chain(&self.target_std);
        if !ok || values.clone().any(|v| !v.is_finite()) || stds.clone().any(|s| !(*s > 0.0)) {
            return Err(ModelError::Invalid(format!(
                "the regressor's scaling does not fit 7 inputs and k = {k} targets"
            )));
        }
        Ok(())
    }

    /// The standardised features of `features`.
    pub fn standardise(&self, features: &[f64; 7]) -> [f32; 7] {
        std::array::from_fn(|j| ((features[j] - self.input_mean[j]) / self.input_std[j]) as f32)
    }

    /// Targets from standardised network outputs.
    pub fn unstandardise(&self, outputs: &[f32]) -> Vec<f32> {
        outputs
            .iter()
            .enumerate()
            .map(|(j, &o)| (self.target_mean[j] + self.target_std[j] * f64::from(o)) as f32)
            .collect()
    }
}

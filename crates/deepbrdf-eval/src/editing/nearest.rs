//! The nearest latent edit: the latent route of editing by optimisation. Where the paper's edit
//! replaces the latent by the regressor's `Phi(alpha')` (eq. 7) and the residual edit adds
//! `Phi(alpha') - Phi(alpha)`, this edit looks for the latent closest to the material's own
//! whose attributes, as a differentiable latent-to-attribute predictor reads them, change as
//! asked: `z' = argmin |z' - z|` subject to `P(z') - P(z) = alpha' - alpha` (the change, not the
//! absolute value: the predictor's reading of a material's own latent is not its fitted
//! attributes, and an unedited material must stay as it is). Every `z'` decodes to a table of
//! the decoder, so the edit stays on its manifold; the material's latent moves no more than the
//! request needs, so what the attributes do not describe moves least.
//!
//! The predictor `P(z) = W z + b` is linear, fitted by least squares to the regressor's own map
//! (the latents `Phi(alpha_i)` of attribute vectors `alpha_i` drawn over the attribute ranges,
//! seeded) in the regressor's feature space (the albedos and `ln(roughness)`), so it needs
//! nothing beyond the representation and its regressor; with 7 attributes and `k >= 7` latent
//! numbers the constraint is met by the minimum-norm step `z' = z + W^+ (f(alpha') - f(alpha))`
//! (`W^+` the Moore-Penrose pseudo-inverse, `f` the features).

use crate::attributes::Attributes;
use crate::error::{EvalError, Result};
use deepbrdf_model::regressor::scaling::features;
use deepbrdf_model::regressor::Regressor;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Attribute vectors the predictor is fitted on, and their seed.
pub const PREDICTOR_SAMPLES: usize = 1000;
const PREDICTOR_SEED: u64 = 46;

/// A linear latent-to-attribute predictor (module documentation).
pub struct AttributePredictor {
    /// 7 x k.
    weights: DMatrix<f64>,
    bias: DVector<f64>,
    /// k x 7.
    pseudo_inverse: DMatrix<f64>,
}

impl AttributePredictor {
    /// The predictor fitted to `regressor`'s map.
    pub fn of(regressor: &Regressor) -> Result<Self> {
        let mut rng = ChaCha8Rng::seed_from_u64(PREDICTOR_SEED);
        let log_uniform = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| {
            (lo.ln() + (hi.ln() - lo.ln()) * rng.random::<f64>()).exp()
        };
        let mut rows: Vec<(Vec<f32>, [f64; 7])> = Vec::with_capacity(PREDICTOR_SAMPLES);
        for _ in 0..PREDICTOR_SAMPLES {
            let mut a = [0.0; 7];
            (0..3).for_each(|c| a[c] = 0.8 * rng.random::<f64>());
            (3..6).for_each(|c| a[c] = log_uniform(&mut rng, 0.005, 0.8));
            a[6] = log_uniform(&mut rng, 0.002, 1.0);
            let z = regressor.predict(&a).map_err(|e| EvalError::method("the regressor", e))?;
            rows.push((z, features(&a).map_err(|e| EvalError::method("the regressor", e))?));
        }
        let k = rows[0].0.len();
        let x = DMatrix::from_fn(rows.len(), k + 1, |i, j| match j < k {
            true => f64::from(rows[i].0[j]),
            false => 1.0,
        });
        let y = DMatrix::from_fn(rows.len(), 7, |i, j| rows[i].1[j]);
        let solution = x
            .svd(true, true)
            .solve(&y, 1e-12)
            .map_err(|e| EvalError::Invalid(format!("fitting the attribute predictor: {e}")))?;
        let weights = solution.rows(0, k).transpose();
        let bias = solution.row(k).transpose();
        let pseudo_inverse = weights
            .clone()
            .pseudo_inverse(1e-9)
            .map_err(|e| EvalError::Invalid(format!("the attribute predictor's inverse: {e}")))?;
        Ok(Self { weights, bias, pseudo_inverse })
    }

    /// The predicted features (albedos, `ln(roughness)`) of latent `z`.
    pub fn predict(&self, z: &[f32]) -> DVector<f64> {
        let z = DVector::from_iterator(z.len(), z.iter().map(|&v| f64::from(v)));
        &self.weights * z + &self.bias
    }

    /// The latent closest to `latent` (of a material whose attributes are `original`) whose
    /// predicted attributes change by `requested - original`.
    pub fn nearest(
        &self,
        latent: &[f32],
        original: &Attributes,
        requested: &Attributes,
    ) -> Result<Vec<f32>> {
        if latent.len() != self.weights.ncols() {
            return Err(EvalError::Invalid(format!(
                "a latent of {} numbers for a predictor of {}",
                latent.len(),
                self.weights.ncols()
            )));
        }
        let feature = |a: &Attributes| {
            features(&a.to_array())
                .map_err(|e| EvalError::Invalid(format!("the attributes of the edit: {e}")))
        };
        let (from, to) = (feature(original)?, feature(requested)?);
        let change = DVector::from_iterator(7, (0..7).map(|i| to[i] - from[i]));
        let step = &self.pseudo_inverse * change;
        Ok(latent.iter().zip(step.iter()).map(|(&z, &d)| z + d as f32).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_model::shipped::{DEFAULT_MODEL_DIR, REGRESSOR_DIR};
    use deepbrdf_model::DeviceKind;
    use std::path::Path;

    /// On the shipped regressor: the nearest latent's predicted attributes change as asked, an
    /// identity edit does not move, and the step has no part the predictor cannot see (the
    /// minimum-norm step).
    #[test]
    fn the_nearest_latent_is_read_as_the_request_with_the_smallest_step() {
        let device = DeviceKind::default_kind().expect("a backend").device().unwrap();
        let path = Path::new(DEFAULT_MODEL_DIR).join(REGRESSOR_DIR).join("deepbrdf.regressor");
        let regressor = Regressor::load(&path, &device).unwrap();
        let p = AttributePredictor::of(&regressor).unwrap();
        let a = Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.05; 3], roughness: 0.1 };
        let z = regressor.predict(&a.to_array()).unwrap();
        let asked = Attributes { roughness: 0.2, diffuse: [0.15, 0.1, 0.05], ..a };
        let nearest = p.nearest(&z, &a, &asked).unwrap();
        let (before, after) = (p.predict(&z), p.predict(&nearest));
        let (from, to) = (features(&a.to_array()).unwrap(), features(&asked.to_array()).unwrap());
        for i in 0..7 {
            let (got, want) = (after[i] - before[i], to[i] - from[i]);
            assert!((got - want).abs() < 1e-4, "{i}: {got} vs {want}");
        }
        // No change asked, no move.
        assert_eq!(p.nearest(&z, &a, &a).unwrap(), z);
        // The step lies in the row space of W: projecting it there changes nothing.
        let step =
            DVector::from_iterator(z.len(), nearest.iter().zip(&z).map(|(a, b)| f64::from(a - b)));
        let projected = &p.pseudo_inverse * (&p.weights * &step);
        assert!((projected - &step).norm() < 1e-3 * step.norm().max(1e-9));
        assert!(p.nearest(&z[1..], &a, &asked).unwrap_err().to_string().contains("latent of"));
    }
}

//! An RGL measurement rendered straight from its evaluator (no MERL table in between), as a
//! [`Brdf`]: the cell rule of `RglBrdf::reciprocal` at the exact direction pair, sampled as a
//! given tabulated BRDF is (the converted table, so both renders draw the same directions and
//! their difference is the tabulation's, not Monte Carlo noise).
use super::{Brdf, MerlBrdf, Rgb};
use crate::geometry::Vec3;
use deepbrdf_data::rgl::RglBrdf;

/// The evaluator of one measurement, sampled as `sampling` is.
pub struct MeasuredBrdf<'a> {
    pub brdf: &'a RglBrdf,
    pub sampling: &'a MerlBrdf<'a>,
}

impl Brdf for MeasuredBrdf<'_> {
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        self.brdf.reciprocal(wi.to_array(), wo.to_array()).map(f64::from)
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        self.sampling.sample(wo, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.sampling.pdf(wi, wo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::rgl::bundled;
    use deepbrdf_data::testing::synthetic_table;

    #[test]
    fn evaluates_the_measurement_and_samples_as_the_table() {
        let name = bundled::names()[0];
        let measured = bundled::load(name).unwrap();
        let table = synthetic_table(3);
        let sampling = MerlBrdf::new(&table);
        let brdf = MeasuredBrdf { brdf: &measured, sampling: &sampling };
        let wo = Vec3::new(0.3, -0.2, 0.93).normalized();
        for u in [[0.1, 0.7], [0.5, 0.5], [0.9, 0.2]] {
            let wi = brdf.sample(wo, u);
            assert_eq!(wi, sampling.sample(wo, u));
            let Some(wi) = wi else { continue };
            assert_eq!(brdf.pdf(wi, wo), sampling.pdf(wi, wo));
            let expected = measured.reciprocal(wi.to_array(), wo.to_array()).map(f64::from);
            assert_eq!(brdf.eval(wi, wo), expected);
            assert!(expected.iter().all(|v| v.is_finite() && *v >= 0.0), "{name}: {expected:?}");
        }
    }
}

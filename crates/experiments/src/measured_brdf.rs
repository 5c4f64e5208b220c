//! An RGL measurement rendered straight from its evaluator (no MERL table in between), as a
//! renderer [`Brdf`]: the cell rule of `RglBrdf::reciprocal` at the exact direction pair, sampled
//! as another BRDF is (the converted table's, so both renders draw the same directions and their
//! difference is the tabulation's, not Monte Carlo noise).
use deepbrdf_data::rgl::RglBrdf;
use deepbrdf_render::brdf::Rgb;
use deepbrdf_render::geometry::Vec3;
use deepbrdf_render::Brdf;

/// The evaluator of one measurement, sampled by `sampler`'s strategy.
pub struct MeasuredBrdf<'a, S: Brdf> {
    pub brdf: &'a RglBrdf,
    pub sampler: &'a S,
}

impl<S: Brdf> Brdf for MeasuredBrdf<'_, S> {
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        self.brdf.reciprocal(wi.to_array(), wo.to_array()).map(f64::from)
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        self.sampler.sample(wo, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.sampler.pdf(wi, wo)
    }
}

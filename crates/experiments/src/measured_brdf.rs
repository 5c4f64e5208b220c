//! An RGL measurement rendered straight from its evaluator (no MERL table in between), as a
//! renderer [`Brdf`]: the cell rule of `RglBrdf::reciprocal` at the exact direction pair, sampled
//! as a given tabulated BRDF is (the converted table, so both renders draw the same directions
//! and their difference is the tabulation's, not Monte Carlo noise).
use deepbrdf_data::rgl::RglBrdf;
use deepbrdf_render::brdf::Rgb;
use deepbrdf_render::geometry::Vec3;
use deepbrdf_render::{Brdf, MerlBrdf};

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

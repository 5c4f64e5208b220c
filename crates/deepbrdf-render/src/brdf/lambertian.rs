//! The Lambertian (ideal diffuse) BRDF, `rho / pi`.

use super::{Brdf, Rgb};
use crate::geometry::Vec3;
use std::f64::consts::FRAC_1_PI;

/// Ideal diffuse reflection of albedo `rho` per channel: `f = rho / pi`.
#[derive(Clone, Copy, Debug)]
pub struct Lambertian {
    pub albedo: Rgb,
}

impl Lambertian {
    pub fn new(albedo: Rgb) -> Self {
        Self { albedo }
    }
}

impl Brdf for Lambertian {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return [0.0; 3];
        }
        self.albedo.map(|a| a * FRAC_1_PI)
    }
}

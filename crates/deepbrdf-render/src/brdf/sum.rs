//! The sum of two BRDFs (e.g. a Lambertian base plus a GGX lobe), sampled as a mixture.

use super::{Brdf, Ggx, Lambertian, Rgb};
use crate::geometry::Vec3;

/// `f = a + b`; `sample` picks `a` with probability `prob_a`, and `pdf` is the mixture density.
pub struct Sum<A, B> {
    pub a: A,
    pub b: B,
    pub prob_a: f64,
}

impl<A: Brdf, B: Brdf> Sum<A, B> {
    /// The sum of `a` and `b`; `prob_a` (clamped to [0.01, 0.99]) is how often `a` is sampled.
    pub fn new(a: A, b: B, prob_a: f64) -> Self {
        Self { a, b, prob_a: prob_a.clamp(0.01, 0.99) }
    }
}

impl Sum<Lambertian, Ggx> {
    /// A plastic-like material: diffuse `albedo` plus a GGX lobe (`alpha`, `f0`), each sampled in
    /// proportion to its (approximate) albedo.
    pub fn plastic(albedo: Rgb, alpha: f64, f0: Rgb) -> Self {
        let d: f64 = albedo.iter().sum();
        let s: f64 = f0.iter().sum();
        Self::new(Lambertian::new(albedo), Ggx::new(alpha, f0), d / (d + s).max(1e-12))
    }
}

impl<A: Brdf, B: Brdf> Brdf for Sum<A, B> {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        let (x, y) = (self.a.eval(wi, wo), self.b.eval(wi, wo));
        [x[0] + y[0], x[1] + y[1], x[2] + y[2]]
    }

    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        if u[0] < self.prob_a {
            self.a.sample(wo, [u[0] / self.prob_a, u[1]])
        } else {
            self.b.sample(wo, [(u[0] - self.prob_a) / (1.0 - self.prob_a), u[1]])
        }
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.prob_a * self.a.pdf(wi, wo) + (1.0 - self.prob_a) * self.b.pdf(wi, wo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::tests::check_sampling;

    #[test]
    fn sum_adds_and_samples_as_mixture() {
        let p = Sum::plastic([0.3, 0.2, 0.1], 0.2, [0.04; 3]);
        let wi = Vec3::from_spherical(0.5, 0.1);
        let wo = Vec3::from_spherical(0.4, 3.0);
        let (l, g) = (p.a.eval(wi, wo), p.b.eval(wi, wo));
        let f = p.eval(wi, wo);
        for c in 0..3 {
            assert_eq!(f[c], l[c] + g[c]);
        }
        let (s, u) = check_sampling(&p, wo, 100_000);
        assert!((s - u).abs() < 0.03 * u, "sampled {s} uniform {u}");
    }
}

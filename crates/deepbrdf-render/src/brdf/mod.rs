//! BRDFs behind one small interface (as tray_rust's `BxDF`): `eval` is required, `sample` and
//! `pdf` default to cosine-weighted hemisphere sampling. A tabulated MERL BRDF, analytic BRDFs
//! and a decoded DeepBRDF latent (which is just another [`deepbrdf_data::MerlTable`]) all plug
//! into the same renderer.
//!
//! Directions are unit vectors in the local shading frame (z = surface normal), `wi` towards the
//! light and `wo` towards the viewer, the argument order of `MerlTable::lookup_interpolated`.

mod ggx;
mod interleaved;
mod lambertian;
mod lobe;
mod measured;
mod merl;
mod sum;
mod table_sampler;

pub use ggx::Ggx;
pub use interleaved::InterleavedTable;
pub use lambertian::Lambertian;
pub use lobe::SamplingLobe;
pub use measured::MeasuredBrdf;
pub use merl::{MerlBrdf, MerlLookup, MerlSampling};
pub use sum::Sum;
pub use table_sampler::TableSampler;

use super::geometry::Vec3;
use std::f64::consts::{FRAC_1_PI, PI};

/// Linear RGB, f64 (reflectance in 1/sr, or radiance).
pub type Rgb = [f64; 3];

/// A bidirectional reflectance distribution function.
pub trait Brdf: Sync {
    /// Reflectance `f(wi, wo)` in 1/sr per colour channel; zero when either direction is below
    /// the horizon (`z <= 0`).
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb;

    /// Draws an incident direction for outgoing `wo` from `u` uniform in [0,1)^2; `None` when the
    /// sample falls below the horizon. Its density is [`Brdf::pdf`]. Default: cosine-weighted.
    fn sample(&self, _wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        Some(sample_cosine_hemisphere(u))
    }

    /// Solid-angle density with which [`Brdf::sample`] draws `wi` given `wo`.
    fn pdf(&self, wi: Vec3, _wo: Vec3) -> f64 {
        cosine_hemisphere_pdf(wi)
    }
}

impl<B: Brdf + ?Sized> Brdf for &B {
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        (**self).eval(wi, wo)
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        (**self).sample(wo, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        (**self).pdf(wi, wo)
    }
}

impl<B: Brdf + ?Sized + Send> Brdf for Box<B> {
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        (**self).eval(wi, wo)
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        (**self).sample(wo, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        (**self).pdf(wi, wo)
    }
}

/// A cosine-distributed direction on the upper hemisphere (Malley's method: a uniform point on
/// the unit disk, concentric mapping of Shirley and Chiu 1997, lifted to the hemisphere).
#[inline]
pub fn sample_cosine_hemisphere(u: [f64; 2]) -> Vec3 {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    let (r, phi) = if a == 0.0 && b == 0.0 {
        (0.0, 0.0)
    } else if a.abs() > b.abs() {
        (a, PI / 4.0 * (b / a))
    } else {
        (b, PI / 2.0 - PI / 4.0 * (a / b))
    };
    let (s, c) = phi.sin_cos();
    let (x, y) = (r * c, r * s);
    Vec3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
}

/// Density of [`sample_cosine_hemisphere`]: `cos(theta) / pi` above the horizon.
#[inline]
pub fn cosine_hemisphere_pdf(wi: Vec3) -> f64 {
    if wi.z > 0.0 {
        wi.z * FRAC_1_PI
    } else {
        0.0
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Monte Carlo check that `sample` draws with density `pdf`: the estimate of
    /// `integral over the hemisphere of g(wi) dwi` by sampling must match the one by uniform
    /// hemisphere sampling, for a smooth test function `g`, and `E[1 / pdf]` over the support must
    /// match its solid angle. Returns (sampled estimate, uniform estimate).
    pub fn check_sampling(brdf: &dyn Brdf, wo: Vec3, n: usize) -> (f64, f64) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // g weights the lobe's neighbourhood, so a pdf error anywhere shows.
        let g = |wi: Vec3| {
            let f = brdf.eval(wi, wo);
            (f[0] + f[1] + f[2]) * wi.z
        };
        let mut sampled = 0.0;
        for _ in 0..n {
            if let Some(wi) = brdf.sample(wo, [rng.random(), rng.random()]) {
                let p = brdf.pdf(wi, wo);
                if p > 0.0 {
                    sampled += g(wi) / p;
                }
            }
        }
        let mut uniform = 0.0;
        for _ in 0..n {
            let z: f64 = rng.random();
            let phi = 2.0 * PI * rng.random::<f64>();
            let r = (1.0 - z * z).max(0.0).sqrt();
            uniform += g(Vec3::new(r * phi.cos(), r * phi.sin(), z)) * 2.0 * PI;
        }
        (sampled / n as f64, uniform / n as f64)
    }

    #[test]
    fn cosine_sampling_matches_its_pdf() {
        let brdf = Lambertian::new([0.5, 0.5, 0.5]);
        let (s, u) = check_sampling(&brdf, Vec3::new(0.0, 0.0, 1.0), 20000);
        // Integral of (3 * 0.5/pi) cos over the hemisphere = 1.5; the sampled estimate is exact
        // (f cos / pdf is constant), the uniform one carries Monte Carlo noise.
        assert!((s - 1.5).abs() < 1e-9, "{s}");
        assert!((u - 1.5).abs() < 0.03, "{u}");
    }
}

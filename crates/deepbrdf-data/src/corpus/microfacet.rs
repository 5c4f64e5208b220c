//! Microfacet specular lobes (Cook & Torrance 1982 in the normalisation of Walter et al. 2007,
//! eq. 20): `f = tint F(wi . h) D(h) G1(wi) G1(wo) / (4 cos_i cos_o)`, with the GGX or the
//! Beckmann distribution and Smith's separable masking for each (Walter et al. 2007, eqs. 25-27
//! for Beckmann, 33-34 for GGX; the GGX terms are [`crate::ggx`]'s).
//!
//! Both distributions take the same `alpha`: their peaks agree, `D(h = n) = 1 / (pi alpha^2)`,
//! and their RMS slopes agree for small alpha, so a Beckmann lobe's GGX-equivalent roughness
//! (the 7-attribute model's) is its alpha.

use super::fresnel::Fresnel;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A microfacet normal distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    /// GGX (Trowbridge-Reitz): Walter et al. 2007, eq. 33.
    Ggx,
    /// Beckmann: Walter et al. 2007, eq. 25.
    Beckmann,
}

impl Distribution {
    /// `D(h)` at `cos_h = h . n`, normalised so that `integral D cos(theta_h) dw = 1`.
    pub fn d(self, alpha: f64, cos_h: f64) -> f64 {
        match self {
            Distribution::Ggx => crate::ggx::distribution(alpha, cos_h),
            Distribution::Beckmann => beckmann(alpha, cos_h),
        }
    }

    /// Smith's masking `G1(v)` of a direction at `cos = v . n > 0`.
    pub fn g1(self, alpha: f64, cos: f64) -> f64 {
        match self {
            Distribution::Ggx => crate::ggx::smith_g1(alpha, cos),
            Distribution::Beckmann => beckmann_g1(alpha, cos),
        }
    }
}

/// Beckmann's distribution `D = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4)` (Walter et al.
/// 2007, eq. 25); 0 for `cos_h <= 0`.
pub fn beckmann(alpha: f64, cos_h: f64) -> f64 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let (a2, c2) = (alpha * alpha, cos_h * cos_h);
    let tan2 = (1.0 - c2) / c2;
    (-tan2 / a2).exp() / (PI * a2 * c2 * c2)
}

/// Smith's masking for Beckmann in Walter et al.'s rational approximation (2007, eq. 27, within
/// 0.35% of the exact `1 / (1 + Lambda)`): with `a = 1 / (alpha tan)`,
/// `G1 = (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2)` for `a < 1.6`, else 1.
pub fn beckmann_g1(alpha: f64, cos: f64) -> f64 {
    if cos >= 1.0 {
        return 1.0;
    }
    let a = cos / (alpha * (1.0 - cos * cos).sqrt());
    if a >= 1.6 {
        return 1.0;
    }
    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
}

/// A specular lobe: distribution, roughness, Fresnel and a tint (a per-channel weight, 1 for a
/// physical interface; a tinted metal or a lobe sharing its interface with another has less).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lobe {
    pub distribution: Distribution,
    /// Roughness alpha (the GGX-equivalent roughness of the 7 attributes).
    pub alpha: f64,
    pub fresnel: Fresnel,
    /// Per-channel weight in [0, 1].
    pub tint: [f64; 3],
}

impl Lobe {
    /// The BRDF (1/sr) at unit directions (wi, wo), z = normal; 0 below the horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        let Some((h, cos_d)) = half_vector(wi, wo) else { return [0.0; 3] };
        let d = self.distribution.d(self.alpha, h[2]);
        let g = self.distribution.g1(self.alpha, wi[2]) * self.distribution.g1(self.alpha, wo[2]);
        let common = d * g / (4.0 * wi[2] * wo[2]);
        let f = self.fresnel.eval(cos_d);
        std::array::from_fn(|c| self.tint[c] * f[c] * common)
    }

    /// Reflectance at normal incidence per channel: `tint F(1)` (the lobe's specular albedo in
    /// the 7-attribute sense).
    pub fn normal_reflectance(&self) -> [f64; 3] {
        let f = self.fresnel.normal();
        std::array::from_fn(|c| self.tint[c] * f[c])
    }
}

/// The half vector of (wi, wo) and `wi . h`, or `None` if either direction is at or below the
/// horizon.
pub fn half_vector(wi: [f64; 3], wo: [f64; 3]) -> Option<([f64; 3], f64)> {
    if wi[2] <= 0.0 || wo[2] <= 0.0 {
        return None;
    }
    let s = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let inv = 1.0 / (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let h = s.map(|v| v * inv);
    Some((h, (wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2]).clamp(0.0, 1.0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo, projected_integral};
    use crate::ggx::{ggx, Ggx};
    use crate::merl::coords::direction;

    fn lobe(distribution: Distribution, alpha: f64, fresnel: Fresnel) -> Lobe {
        Lobe { distribution, alpha, fresnel, tint: [1.0; 3] }
    }

    #[test]
    fn ggx_with_schlick_is_the_attribute_models_lobe() {
        let f0 = [0.04, 0.5, 0.9];
        let ours = lobe(Distribution::Ggx, 0.3, Fresnel::Schlick { f0 });
        let theirs = Ggx { alpha: 0.3, f0, diffuse: [0.0; 3] };
        for (a, b) in [((0.4, 0.1), (1.0, 2.5)), ((0.0, 0.0), (0.2, 1.0)), ((1.2, 0.3), (1.4, 3.0))]
        {
            let (wi, wo) = (direction(a.0, a.1), direction(b.0, b.1));
            let (x, y) = (ours.eval(wi, wo), ggx(&theirs, wi, wo));
            for c in 0..3 {
                assert!((x[c] - y[c]).abs() <= 1e-12 * y[c].max(1.0), "{x:?} {y:?}");
            }
        }
    }

    #[test]
    fn known_values_and_reciprocity() {
        // Normal incidence and exitance: D = 1 / (pi alpha^2) for both, G1 = 1:
        // f = F(1) / (4 pi alpha^2).
        let n = [0.0, 0.0, 1.0];
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            let l = lobe(dist, 0.2, Fresnel::Dielectric { eta: 1.5 });
            let expected = 0.04 / (4.0 * PI * 0.04);
            assert!((l.eval(n, n)[0] - expected).abs() < 1e-12, "{dist:?}");
            assert_reciprocal(|a, b| l.eval(a, b));
            assert_eq!(l.eval(n, direction(1.7, 0.0)), [0.0; 3]);
        }
    }

    #[test]
    fn beckmann_is_normalised_and_its_masking_close_to_exact() {
        for alpha in [0.05, 0.3, 0.8] {
            let integral = projected_integral(|c| beckmann(alpha, c));
            assert!((integral - 1.0).abs() < 1e-3, "alpha {alpha}: {integral}");
        }
        // The exact Smith G1 for Beckmann, 1 / (1 + Lambda) with
        // Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)) (Walter et al. 2007, eq. 26),
        // with erf(a) from its Maclaurin series (a < 1.6 converges in 40 terms).
        let erf = |a: f64| {
            let (mut term, mut sum) = (a, a);
            for n in 1..60 {
                term *= -a * a / n as f64;
                sum += term / (2 * n + 1) as f64;
            }
            2.0 / PI.sqrt() * sum
        };
        for a in [0.2, 0.5, 1.0, 1.5] {
            let lambda = (erf(a) - 1.0) / 2.0 + (-a * a).exp() / (2.0 * a * PI.sqrt());
            let exact = 1.0 / (1.0 + lambda);
            // cos such that cos / (alpha sin) = a at alpha 0.5.
            let t = (1.0 / (0.5 * a)).atan();
            let approx = beckmann_g1(0.5, t.cos());
            assert!((approx / exact - 1.0).abs() < 0.0035, "a {a}: {approx} vs {exact}");
        }
    }

    #[test]
    fn a_white_lobe_reflects_at_most_everything() {
        // F = 1: the albedo is the masked fraction, <= 1, and near 1 for a smooth lobe at
        // normal incidence: there it is `integral D cos(theta_h) G1(wo) dw_h` over theta_h <
        // 45 deg (beyond, wo is below the horizon), and GGX's tail past 45 deg holds
        // alpha^2 / (alpha^2 + 1) = 3.8% at alpha 0.2.
        let white = Fresnel::Schlick { f0: [1.0; 3] };
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            for alpha in [0.2, 0.5, 1.0] {
                for theta_i in [0.0, 0.7, 1.3] {
                    let l = lobe(dist, alpha, white);
                    let a = directional_albedo(|x, y| l.eval(x, y), theta_i, 400)[0];
                    assert!(a <= 1.0 + 2e-3, "{dist:?} alpha {alpha} theta {theta_i}: {a}");
                    if alpha == 0.2 && theta_i == 0.0 {
                        assert!(a > 0.94, "{dist:?}: {a}");
                    }
                }
            }
        }
    }
}

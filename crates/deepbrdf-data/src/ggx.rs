//! The analytic GGX microfacet BRDF, the one home of its formula (Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces", eqs. 33-34, with the separable
//! Smith shadowing term and Schlick's 1994 Fresnel approximation), plus a Lambertian term:
//!
//! `f = diffuse / pi + D(h) G1(wi) G1(wo) F(wi . h) / (4 cos_i cos_o)`.
//!
//! The renderer's GGX lobe (`deepbrdf-render`) evaluates it through [`ggx`]; tests tabulate it
//! on the MERL grid ([`crate::corpus::tabulate`]), and the corpus' microfacet lobes
//! ([`crate::corpus::microfacet`]) use its distribution, masking and Fresnel terms.

use std::f64::consts::PI;

/// Parameters of an RGB GGX lobe plus a Lambertian term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    /// GGX roughness alpha (> 0).
    pub alpha: f64,
    /// Reflectance at normal incidence per channel (Schlick).
    pub f0: [f64; 3],
    /// Diffuse albedo per channel (Lambertian term albedo / pi).
    pub diffuse: [f64; 3],
}

/// GGX normal distribution `D(h) = alpha^2 / (pi ((alpha^2 - 1) cos^2 + 1)^2)` (Walter et al.
/// 2007, eq. 33), normalised so that `integral D cos(theta_h) dw = 1`; 0 for `cos_h <= 0`.
#[inline]
pub fn distribution(alpha: f64, cos_h: f64) -> f64 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = (a2 - 1.0) * cos_h * cos_h + 1.0;
    a2 / (PI * d * d)
}

/// Smith's masking for GGX, `G1(v) = 2 cos / (cos + sqrt(alpha^2 + (1 - alpha^2) cos^2))`
/// (Walter et al. 2007, eq. 34).
#[inline]
pub fn smith_g1(alpha: f64, cos: f64) -> f64 {
    let a2 = alpha * alpha;
    2.0 * cos / (cos + (a2 + (1.0 - a2) * cos * cos).sqrt())
}

/// The BRDF (1/sr) of `lobe` at unit directions (wi, wo), z = normal; 0 below the horizon.
/// `F = f0 + (1 - f0) (1 - wi . h)^5`.
pub fn ggx(lobe: &Ggx, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
    let (ci, co) = (wi[2], wo[2]);
    if ci <= 0.0 || co <= 0.0 {
        return [0.0; 3];
    }
    let s = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let inv = 1.0 / (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let h = [s[0] * inv, s[1] * inv, s[2] * inv];
    let d = distribution(lobe.alpha, h[2]);
    let g = smith_g1(lobe.alpha, ci) * smith_g1(lobe.alpha, co);
    let cd = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2];
    let common = d * g / (4.0 * ci * co);
    std::array::from_fn(|c| lobe.diffuse[c] / PI + schlick(lobe.f0[c], cd) * common)
}

/// Schlick's 1994 approximation of the Fresnel reflectance at `cos_d = wi . h` (clamped to
/// [0, 1]): `F = f0 + (1 - f0) (1 - cos_d)^5`.
#[inline]
pub fn schlick(f0: f64, cos_d: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - cos_d.clamp(0.0, 1.0)).powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::coords::direction;

    #[test]
    fn ggx_known_values() {
        let lobe = Ggx { alpha: 0.5, f0: [1.0; 3], diffuse: [0.0; 3] };
        // Normal incidence and exitance: D = 1 / (pi alpha^2), G1 = 1, F = 1:
        // f = 1 / (4 pi alpha^2).
        let n = [0.0, 0.0, 1.0];
        let f = ggx(&lobe, n, n);
        assert!((f[0] - 1.0 / (4.0 * PI * 0.25)).abs() < 1e-12);
        // Reciprocal.
        let (a, b) = (direction(0.4, 0.1), direction(1.0, 2.5));
        let (fab, fba) = (ggx(&lobe, a, b), ggx(&lobe, b, a));
        for c in 0..3 {
            assert!((fab[c] - fba[c]).abs() <= 1e-12 * fab[c].abs().max(1.0));
        }
        assert_eq!(ggx(&lobe, a, direction(1.7, 0.0)), [0.0; 3]);
        // The Lambertian part adds exactly albedo / pi.
        let with_diffuse = Ggx { diffuse: [0.3; 3], ..lobe };
        let f = ggx(&with_diffuse, a, b);
        assert!((f[0] - fab[0] - 0.3 / PI).abs() < 1e-12);
    }

    #[test]
    fn distribution_is_normalised() {
        for alpha in [0.05, 0.3, 0.8] {
            let integral = crate::corpus::checks::projected_integral(|c| distribution(alpha, c));
            assert!((integral - 1.0).abs() < 1e-3, "alpha {alpha}: {integral}");
        }
    }
}

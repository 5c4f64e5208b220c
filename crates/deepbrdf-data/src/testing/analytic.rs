//! Analytic BRDFs and tables tabulated from them, for tests in this crate and others (a renderer
//! can check itself against a closed form): a Lambertian constant and a GGX microfacet lobe
//! (Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", with the
//! separable Smith shadowing term and Schlick's Fresnel approximation).

use crate::merl::coords::HalfDiff;
use crate::merl::grid::{phi_d_of, theta_d_of, theta_h_of};
use crate::merl::MerlTable;
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

/// The GGX BRDF (1/sr) of `lobe` at unit directions (wi, wo), z = normal; 0 below the horizon.
///
/// `f = diffuse / pi + D(h) G1(wi) G1(wo) F(wi . h) / (4 cos_i cos_o)` with
/// `D = alpha^2 / (pi (cos^2 theta_h (alpha^2 - 1) + 1)^2)`,
/// `G1(v) = 2 cos_v / (cos_v + sqrt(alpha^2 + (1 - alpha^2) cos_v^2))`,
/// `F = f0 + (1 - f0) (1 - wi . h)^5`.
pub fn ggx(lobe: &Ggx, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
    let (ci, co) = (wi[2], wo[2]);
    if ci <= 0.0 || co <= 0.0 {
        return [0.0; 3];
    }
    let s = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let h = [s[0] / n, s[1] / n, s[2] / n];
    let a2 = lobe.alpha * lobe.alpha;
    let ch = h[2];
    let denom = ch * ch * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * denom * denom);
    let g1 = |c: f64| 2.0 * c / (c + (a2 + (1.0 - a2) * c * c).sqrt());
    let g = g1(ci) * g1(co);
    let cd = (wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2]).clamp(0.0, 1.0);
    let schlick = (1.0 - cd).powi(5);
    std::array::from_fn(|c| {
        let f = lobe.f0[c] + (1.0 - lobe.f0[c]) * schlick;
        lobe.diffuse[c] / PI + d * g * f / (4.0 * ci * co)
    })
}

/// Tabulates `brdf(wi, wo) -> rgb` (1/sr) on the MERL grid: each valid cell gets the value at
/// its sample angles ([`crate::merl::grid`]) with phi_h = 0, as the NBRDF tabulation does.
pub fn tabulate(brdf: impl Fn([f64; 3], [f64; 3]) -> [f64; 3]) -> MerlTable {
    MerlTable::from_fn(|h, d, p| {
        let angles = HalfDiff {
            theta_h: theta_h_of(h),
            phi_h: 0.0,
            theta_d: theta_d_of(d),
            phi_d: phi_d_of(p),
        };
        let (wi, wo) = angles.to_dirs();
        brdf(wi, wo).map(|v| v as f32)
    })
}

/// A Lambertian table: albedo / pi in every valid cell.
pub fn lambertian_table(albedo: [f64; 3]) -> MerlTable {
    let rgb = albedo.map(|a| (a / PI) as f32);
    MerlTable::from_fn(|_, _, _| rgb)
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
        assert_eq!(ggx(&lobe, a, b), ggx(&lobe, b, a));
        assert_eq!(ggx(&lobe, a, direction(1.7, 0.0)), [0.0; 3]);
        // Lambertian part alone.
        let lobe = Ggx { alpha: 0.5, f0: [0.0; 3], diffuse: [0.3; 3] };
        let f = ggx(&lobe, a, b);
        assert!(f[0] > 0.3 / PI);
    }
}

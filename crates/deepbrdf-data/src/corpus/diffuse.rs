//! Diffuse bases: Lambert's constant `albedo / pi` and the rough diffuse model of Oren & Nayar
//! 1994 ("Generalization of Lambert's Reflectance Model", SIGGRAPH, the qualitative model of
//! eq. 30): `f = albedo / pi (A + B max(0, cos(phi_i - phi_o)) sin(a) tan(b))` with
//! `A = 1 - 0.5 s^2 / (s^2 + 0.33)`, `B = 0.45 s^2 / (s^2 + 0.09)`, `a = max(theta_i, theta_o)`,
//! `b = min(theta_i, theta_o)` and `s` (sigma) the standard deviation of the facet angle in
//! radians. At sigma 0 it is Lambert's.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A diffuse base.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Diffuse {
    /// `albedo / pi`.
    Lambertian { albedo: [f64; 3] },
    /// Oren-Nayar with facet-slope deviation `sigma` (radians).
    OrenNayar { albedo: [f64; 3], sigma: f64 },
}

impl Diffuse {
    /// The albedo per channel (the directional albedo at normal incidence).
    pub fn albedo(&self) -> [f64; 3] {
        match *self {
            Diffuse::Lambertian { albedo } | Diffuse::OrenNayar { albedo, .. } => albedo,
        }
    }

    /// The same base with another albedo.
    pub fn with_albedo(self, albedo: [f64; 3]) -> Self {
        match self {
            Diffuse::Lambertian { .. } => Diffuse::Lambertian { albedo },
            Diffuse::OrenNayar { sigma, .. } => Diffuse::OrenNayar { albedo, sigma },
        }
    }

    /// The BRDF (1/sr) at unit directions (wi, wo), z = normal; 0 below the horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        let scale = match *self {
            Diffuse::Lambertian { .. } => 1.0,
            Diffuse::OrenNayar { sigma, .. } => oren_nayar_factor(sigma, wi, wo),
        };
        self.albedo().map(|a| a / PI * scale)
    }
}

/// `A + B max(0, cos(phi_i - phi_o)) sin(a) tan(b)` of the qualitative Oren-Nayar model.
fn oren_nayar_factor(sigma: f64, wi: [f64; 3], wo: [f64; 3]) -> f64 {
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    let (sin_i, sin_o) = (sin_theta(wi), sin_theta(wo));
    if sin_i < 1e-12 || sin_o < 1e-12 {
        return a;
    }
    let cos_dphi = ((wi[0] * wo[0] + wi[1] * wo[1]) / (sin_i * sin_o)).max(0.0);
    // sin(max) tan(min): the larger polar angle has the larger sine and the smaller cosine.
    let (sin_max, tan_min) = match wi[2] < wo[2] {
        true => (sin_i, sin_o / wo[2]),
        false => (sin_o, sin_i / wi[2]),
    };
    a + b * cos_dphi * sin_max * tan_min
}

fn sin_theta(w: [f64; 3]) -> f64 {
    (w[0] * w[0] + w[1] * w[1]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo};
    use crate::merl::coords::direction;

    #[test]
    fn lambertian_is_albedo_over_pi_and_reflects_its_albedo() {
        let d = Diffuse::Lambertian { albedo: [0.2, 0.5, 0.9] };
        let f = d.eval(direction(0.3, 0.0), direction(1.1, 2.0));
        assert_eq!(f, [0.2 / PI, 0.5 / PI, 0.9 / PI]);
        let a = directional_albedo(|x, y| d.eval(x, y), 0.8, 200);
        assert!((a[2] - 0.9).abs() < 1e-4, "{a:?}");
        assert_eq!(d.eval(direction(0.3, 0.0), direction(1.7, 0.0)), [0.0; 3]);
    }

    #[test]
    fn oren_nayar_known_values_reciprocity_and_energy() {
        let albedo = [1.0; 3];
        // sigma 0 is Lambert's.
        let smooth = Diffuse::OrenNayar { albedo, sigma: 0.0 };
        let (a, b) = (direction(0.4, 0.1), direction(1.0, 2.5));
        assert!((smooth.eval(a, b)[0] - 1.0 / PI).abs() < 1e-15);
        // A closed-form value: theta_i = 60 deg, theta_o = 30 deg, same azimuth, sigma 0.5:
        // A = 1 - 0.125 / 0.58, B = 0.1125 / 0.34, sin(60) tan(30) = 0.5.
        let rough = Diffuse::OrenNayar { albedo, sigma: 0.5 };
        let f = rough.eval(direction(PI / 3.0, 0.3), direction(PI / 6.0, 0.3))[0];
        let expected = (1.0 - 0.125 / 0.58 + 0.1125 / 0.34 * 0.5) / PI;
        assert!((f - expected).abs() < 1e-12, "{f} vs {expected}");
        // Opposite azimuths: the B term vanishes.
        let f = rough.eval(direction(PI / 3.0, 0.0), direction(PI / 6.0, PI))[0];
        assert!((f - (1.0 - 0.125 / 0.58) / PI).abs() < 1e-12);
        assert_reciprocal(|x, y| rough.eval(x, y));
        // At normal incidence the albedo is A <= 1; the model stays below 1 elsewhere too.
        for sigma in [0.3, 1.0] {
            let on = Diffuse::OrenNayar { albedo, sigma };
            let s2 = sigma * sigma;
            let at_normal = directional_albedo(|x, y| on.eval(x, y), 0.0, 200)[0];
            assert!((at_normal - (1.0 - 0.5 * s2 / (s2 + 0.33))).abs() < 1e-4, "{at_normal}");
            for theta_i in [0.5, 1.0, 1.4] {
                let a = directional_albedo(|x, y| on.eval(x, y), theta_i, 200)[0];
                assert!(a <= 1.0, "sigma {sigma} theta {theta_i}: {a}");
            }
        }
    }
}

//! Sheen for fabrics: the "Charlie" distribution of Estevez & Kulla 2017 ("Production Friendly
//! Microfacet Sheen BRDF", Sony Imageworks), `D(h) = (2 + 1/r) sin(theta_h)^(1/r) / (2 pi)`
//! (an inverted Gaussian-like lobe of fibres, brightest at grazing half vectors), with the
//! visibility term of Neubelt & Pettineo 2013 ("Crafting a Next-Gen Material Pipeline for The
//! Order: 1886"), `V = 1 / (4 (cos_i + cos_o - cos_i cos_o))`, as Filament uses it:
//! `f = colour D(h) V`.

use super::microfacet::half_vector;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A sheen lobe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sheen {
    /// Per-channel weight in [0, 1].
    pub colour: [f64; 3],
    /// The Charlie roughness r in (0, 1]: small r concentrates the sheen at grazing angles.
    pub roughness: f64,
}

impl Sheen {
    /// The BRDF (1/sr) at unit directions (wi, wo), z = normal; 0 below the horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        let Some((h, _)) = half_vector(wi, wo) else { return [0.0; 3] };
        let v = 1.0 / (4.0 * (wi[2] + wo[2] - wi[2] * wo[2]));
        let d = charlie(self.roughness, h[2]);
        self.colour.map(|c| c * d * v)
    }
}

/// The Charlie distribution at `cos_h`, normalised so that `integral D cos(theta_h) dw = 1`.
pub fn charlie(r: f64, cos_h: f64) -> f64 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
    let inv = 1.0 / r;
    (2.0 + inv) * sin_h.powf(inv) / (2.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo, projected_integral};
    use crate::merl::coords::direction;

    #[test]
    fn charlie_is_normalised() {
        for r in [0.1, 0.4, 1.0] {
            let integral = projected_integral(|c| charlie(r, c));
            assert!((integral - 1.0).abs() < 1e-3, "r {r}: {integral}");
        }
    }

    #[test]
    fn known_value_reciprocity_and_energy() {
        // Retro-reflection at normal incidence: h = n, sin = 0, D = 0.
        let sheen = Sheen { colour: [1.0; 3], roughness: 0.5 };
        let n = [0.0, 0.0, 1.0];
        assert_eq!(sheen.eval(n, n), [0.0; 3]);
        // wi = wo at 60 degrees: h = wi, D = 4 sin^2(60) / (2 pi),
        // V = 1 / (4 (1 - 0.25)) = 1/3.
        let w = direction(PI / 3.0, 0.2);
        let expected = 4.0 * 0.75 / (2.0 * PI) / 3.0;
        assert!((sheen.eval(w, w)[0] - expected).abs() < 1e-12);
        assert_reciprocal(|a, b| sheen.eval(a, b));
        for r in [0.1, 0.5, 1.0] {
            let s = Sheen { roughness: r, ..sheen };
            for theta_i in [0.0, 0.8, 1.4] {
                let a = directional_albedo(|x, y| s.eval(x, y), theta_i, 300)[0];
                assert!(a > 0.0 && a <= 1.0, "r {r} theta {theta_i}: {a}");
            }
        }
    }
}

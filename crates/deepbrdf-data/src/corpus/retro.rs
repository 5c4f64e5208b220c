//! A retro-reflective lobe (road signs, some fabrics and paints): a Lafortune et al. 1997
//! ("Non-Linear Approximation of Reflectance Functions", SIGGRAPH) cosine lobe with
//! `Cx = Cy = Cz = 1`, which points back at the light: `f = colour (n + 1) / (2 pi)
//! max(0, wi . wo)^n`. The normalisation makes its directional albedo at most the colour:
//! `integral (wi . wo)^n cos_o dwo <= integral over the hemisphere about wi = 2 pi / (n + 1)`.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A retro-reflective lobe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Retro {
    /// Per-channel weight in [0, 1].
    pub colour: [f64; 3],
    /// The cosine exponent n (>= 1): larger is narrower.
    pub exponent: f64,
}

impl Retro {
    /// The BRDF (1/sr) at unit directions (wi, wo), z = normal; 0 below the horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        let c = (wi[0] * wo[0] + wi[1] * wo[1] + wi[2] * wo[2]).max(0.0);
        let lobe = (self.exponent + 1.0) / (2.0 * PI) * c.powf(self.exponent);
        self.colour.map(|k| k * lobe)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo};
    use crate::merl::coords::direction;

    #[test]
    fn known_value_reciprocity_and_energy() {
        let retro = Retro { colour: [1.0, 0.5, 0.0], exponent: 20.0 };
        // Back towards the light: (n + 1) / (2 pi) times the colour.
        let w = direction(0.6, 1.0);
        let f = retro.eval(w, w);
        assert!((f[0] - 21.0 / (2.0 * PI)).abs() < 1e-12 && (f[1] - f[0] / 2.0).abs() < 1e-15);
        // Mirror direction at 60 degrees: wi . wo = cos 120 < 0, nothing.
        assert_eq!(retro.eval(direction(PI / 3.0, 0.0), direction(PI / 3.0, PI)), [0.0; 3]);
        assert_reciprocal(|a, b| retro.eval(a, b));
        // At normal incidence the albedo is (n + 1) / (n + 2) exactly; elsewhere <= 1.
        for n in [1.0, 20.0] {
            let r = Retro { colour: [1.0; 3], exponent: n };
            let a = directional_albedo(|x, y| r.eval(x, y), 0.0, 400)[0];
            assert!((a - (n + 1.0) / (n + 2.0)).abs() < 2e-3, "n {n}: {a}");
            for theta_i in [0.7, 1.4] {
                let a = directional_albedo(|x, y| r.eval(x, y), theta_i, 400)[0];
                assert!(a <= 1.0, "n {n} theta {theta_i}: {a}");
            }
        }
    }
}

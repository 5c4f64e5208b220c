//! A clear coat: a smooth-to-glossy dielectric GGX lobe over a base, the base attenuated by the
//! coat's Fresnel transmission on the way in and out, `f = f_coat + (1 - F(cos_i)) (1 -
//! F(cos_o)) f_base`, with F the exact dielectric reflectance at the macro-surface angles. This
//! is the simplest energy-aware layering (no refraction of the base's directions and no
//! inter-reflection between the layers; Weidlich & Wilkie 2007, "Arbitrarily Layered
//! Micro-Facet Surfaces", add both); it is reciprocal and keeps the coat's highlight separate
//! from the base's, the two highlights of a car paint.

use super::fresnel::{dielectric, Fresnel};
use super::microfacet::{Distribution, Lobe};
use serde::{Deserialize, Serialize};

/// A dielectric coat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coat {
    /// The coat's index of refraction (> 1).
    pub eta: f64,
    /// The coat's GGX roughness alpha.
    pub alpha: f64,
}

impl Coat {
    /// The coat's own reflection: a white GGX lobe with the exact dielectric Fresnel.
    pub fn lobe(&self) -> Lobe {
        Lobe {
            distribution: Distribution::Ggx,
            alpha: self.alpha,
            fresnel: Fresnel::Dielectric { eta: self.eta },
            tint: [1.0; 3],
        }
    }

    /// The fraction of light through the coat and back at normal incidence, `(1 - F(1))^2`.
    pub fn normal_transmission(&self) -> f64 {
        (1.0 - dielectric(self.eta, 1.0)).powi(2)
    }

    /// The coated BRDF (1/sr) at (wi, wo), given the base's value `base` there.
    pub fn eval(&self, base: [f64; 3], wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        let t = (1.0 - dielectric(self.eta, wi[2])) * (1.0 - dielectric(self.eta, wo[2]));
        let coat = self.lobe().eval(wi, wo);
        std::array::from_fn(|c| coat[c] + t * base[c])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo};
    use crate::corpus::diffuse::Diffuse;
    use crate::merl::coords::direction;
    use std::f64::consts::PI;

    #[test]
    fn known_values_reciprocity_and_energy() {
        let coat = Coat { eta: 1.5, alpha: 0.1 };
        let (a, b) = (direction(0.4, 0.1), direction(1.0, 2.5));
        // Over nothing it is the coat's lobe.
        assert_eq!(coat.eval([0.0; 3], a, b), coat.lobe().eval(a, b));
        // Away from the coat's highlight a Lambertian base shows through at (1 - F)^2 at
        // normal incidence: 0.96^2 / pi for albedo 1.
        assert!((coat.normal_transmission() - 0.9216).abs() < 1e-12);
        let white = Diffuse::Lambertian { albedo: [1.0; 3] };
        let n = [0.0, 0.0, 1.0];
        let f = coat.eval(white.eval(n, n), n, n);
        let lobe_peak = 0.04 / (4.0 * PI * 0.01);
        assert!((f[0] - lobe_peak - 0.9216 / PI).abs() < 1e-12);
        let coated = |x, y| coat.eval(white.eval(x, y), x, y);
        assert_reciprocal(coated);
        // A white base under the coat reflects at most everything.
        for theta_i in [0.0, 0.8, 1.4] {
            let a = directional_albedo(coated, theta_i, 600)[0];
            assert!(a <= 1.0 && a > 0.5, "theta {theta_i}: {a}");
        }
    }
}

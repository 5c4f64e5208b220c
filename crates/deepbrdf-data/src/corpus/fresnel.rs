//! Fresnel reflectance of a smooth interface, unpolarised light: Schlick's approximation (the
//! project's 7-attribute model, [`crate::ggx::schlick`]), the exact dielectric formula (Walter et
//! al. 2007, eq. 22) and the exact conductor formula for a complex index `eta + i k` (Born &
//! Wolf, Principles of Optics, §14.2; in the form of pbrt-v3 §8.2.1, `FrConductor`).

use serde::{Deserialize, Serialize};

/// The Fresnel term of a microfacet lobe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Fresnel {
    /// Schlick's approximation with reflectance `f0` at normal incidence per channel.
    Schlick { f0: [f64; 3] },
    /// A dielectric of relative index `eta` (> 1: from air into the material), the same in
    /// every channel.
    Dielectric { eta: f64 },
    /// A conductor of complex index `eta + i k` per channel (from air).
    Conductor { eta: [f64; 3], k: [f64; 3] },
}

impl Fresnel {
    /// The reflectance per channel at `cos_d`, the cosine between the incident direction and
    /// the microfacet normal.
    pub fn eval(&self, cos_d: f64) -> [f64; 3] {
        match *self {
            Fresnel::Schlick { f0 } => f0.map(|f| crate::ggx::schlick(f, cos_d)),
            Fresnel::Dielectric { eta } => [dielectric(eta, cos_d); 3],
            Fresnel::Conductor { eta, k } => {
                std::array::from_fn(|c| conductor(eta[c], k[c], cos_d))
            }
        }
    }

    /// The reflectance at normal incidence (`cos_d = 1`).
    pub fn normal(&self) -> [f64; 3] {
        self.eval(1.0)
    }
}

/// Exact unpolarised Fresnel reflectance of a dielectric of relative index `eta` at `cos` (its
/// absolute value; Walter et al. 2007, eq. 22): with `g^2 = eta^2 - 1 + c^2`,
/// `F = (g - c)^2 / (2 (g + c)^2) (1 + ((c (g + c) - 1) / (c (g - c) + 1))^2)`, and 1 under
/// total internal reflection (`g^2 < 0`, only for `eta < 1`).
pub fn dielectric(eta: f64, cos: f64) -> f64 {
    let c = cos.abs().min(1.0);
    let g2 = eta * eta - 1.0 + c * c;
    if g2 < 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// Normal-incidence reflectance of a dielectric: `((eta - 1) / (eta + 1))^2`.
pub fn dielectric_f0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// The index `eta >= 1` whose normal-incidence reflectance is `f0` (in [0, 1)): the inverse of
/// [`dielectric_f0`], `eta = (1 + sqrt f0) / (1 - sqrt f0)`.
pub fn eta_of_f0(f0: f64) -> f64 {
    let s = f0.clamp(0.0, 1.0 - 1e-12).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// Exact unpolarised Fresnel reflectance of a conductor of complex index `eta + i k` at `cos`
/// (clamped to [0, 1]). With `s^2 = 1 - c^2`, `t0 = eta^2 - k^2 - s^2`,
/// `a^2 + b^2 = sqrt(t0^2 + 4 eta^2 k^2)`, `a = sqrt((a^2 + b^2 + t0) / 2)`:
/// `Rs = (a^2 + b^2 + c^2 - 2 a c) / (a^2 + b^2 + c^2 + 2 a c)`,
/// `Rp = Rs (c^2 (a^2 + b^2) + s^4 - 2 a c s^2) / (c^2 (a^2 + b^2) + s^4 + 2 a c s^2)`,
/// `F = (Rs + Rp) / 2`. With `k = 0` it is [`dielectric`].
pub fn conductor(eta: f64, k: f64, cos: f64) -> f64 {
    let c = cos.clamp(0.0, 1.0);
    let (c2, s2) = (c * c, 1.0 - c * c);
    let t0 = eta * eta - k * k - s2;
    let a2b2 = (t0 * t0 + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let (t1, t2) = (a2b2 + c2, 2.0 * a * c);
    let rs = (t1 - t2) / (t1 + t2);
    let (t3, t4) = (c2 * a2b2 + s2 * s2, t2 * s2);
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rs + rp)
}

/// Normal-incidence reflectance of a conductor: `((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2)`.
pub fn conductor_f0(eta: f64, k: f64) -> f64 {
    ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_known_values() {
        // Normal incidence: ((1.5 - 1) / 2.5)^2 = 0.04; grazing: 1; index 1: no interface.
        assert!((dielectric(1.5, 1.0) - 0.04).abs() < 1e-15);
        assert!((dielectric(1.5, 0.0) - 1.0).abs() < 1e-12);
        assert!(dielectric(1.0, 0.7).abs() < 1e-15);
        // Brewster's angle tan(theta_B) = eta: Rp = 0, so F = Rs / 2 with
        // Rs = ((cos_i - eta cos_t) / (cos_i + eta cos_t))^2 (Snell: sin_t = sin_i / eta).
        let eta: f64 = 1.5;
        let ti = eta.atan();
        let ct = (1.0 - (ti.sin() / eta).powi(2)).sqrt();
        let rs = ((ti.cos() - eta * ct) / (ti.cos() + eta * ct)).powi(2);
        assert!((dielectric(eta, ti.cos()) - rs / 2.0).abs() < 1e-14);
        // Total internal reflection from inside glass beyond the critical angle.
        assert_eq!(dielectric(1.0 / 1.5, 0.3), 1.0);
        for eta in [1.3, 1.5, 2.0] {
            assert!((dielectric(eta, 1.0) - dielectric_f0(eta)).abs() < 1e-15);
            assert!((eta_of_f0(dielectric_f0(eta)) - eta).abs() < 1e-12);
            // Monotone in the angle.
            let mut last = 0.0;
            for i in (0..=100).rev() {
                let f = dielectric(eta, i as f64 / 100.0);
                assert!(f >= last - 1e-15 && f <= 1.0);
                last = f;
            }
        }
    }

    #[test]
    fn conductor_known_values() {
        // k = 0 is the dielectric formula; normal incidence matches the closed form; grazing
        // reflects everything.
        for c in [0.05, 0.3, 0.7, 1.0] {
            assert!((conductor(1.5, 0.0, c) - dielectric(1.5, c)).abs() < 1e-14, "cos {c}");
        }
        for (eta, k) in [(0.18, 3.07), (1.36, 7.59), (2.9, 0.1)] {
            assert!((conductor(eta, k, 1.0) - conductor_f0(eta, k)).abs() < 1e-14);
            assert!((conductor(eta, k, 0.0) - 1.0).abs() < 1e-12);
            let f = conductor(eta, k, 0.5);
            assert!(f > 0.0 && f < 1.0);
        }
        let gold = Fresnel::Conductor { eta: [0.18, 0.46, 1.37], k: [3.07, 2.41, 1.83] };
        let f0 = gold.normal();
        assert!(f0[0] > f0[1] && f0[1] > f0[2], "gold is yellow: {f0:?}");
    }

    #[test]
    fn schlick_is_the_attribute_models() {
        let f = Fresnel::Schlick { f0: [0.04, 0.5, 1.0] };
        assert_eq!(f.normal(), [0.04, 0.5, 1.0]);
        assert_eq!(f.eval(0.0), [1.0; 3]);
    }
}

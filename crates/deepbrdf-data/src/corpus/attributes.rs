//! The known attributes of a corpus material in the project's 7-attribute terms (Hu et al. 2020,
//! §5.1, eq. (6): diffuse albedo RGB, specular albedo RGB, roughness; defined in
//! `deepbrdf-eval`'s `attributes` module through a Lambertian + GGX model), computed from the
//! parameters, and the edits whose answer is known: the material with one attribute changed.
//!
//! - **diffuse**: the diffuse base's albedo times the coat's normal transmission
//!   `(1 - F_coat(1))^2` (sheen and retro-reflection are not part of it); 0 without a base.
//! - **specular**: the normal-incidence reflectance of the specular components, the coat's
//!   `F(1)` plus the lobes' `tint F(1)` times the coat's transmission (at most 1).
//! - **roughness**: the alpha of the main lobe, the specular component (lobe or coat) with the
//!   largest mean normal-incidence reflectance; 1 (the widest lobe) without one.
//!
//! Edits keep every parameter they do not ask for, and clamp to the valid ranges
//! ([`super::material`]); the edited material's [`Material::attributes`] say what was reached.

use super::diffuse::Diffuse;
use super::fresnel::{dielectric_f0, eta_of_f0, Fresnel};
use super::material::{Material, ALPHA_RANGE, DIELECTRIC_ETA_RANGE};
use serde::{Deserialize, Serialize};

/// The 7 attributes of a corpus material, as plain numbers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnownAttributes {
    /// Diffuse albedo per channel, in [0, 1].
    pub diffuse: [f64; 3],
    /// Specular albedo (normal-incidence reflectance) per channel, in [0, 1].
    pub specular: [f64; 3],
    /// GGX-equivalent alpha of the main lobe.
    pub roughness: f64,
}

impl KnownAttributes {
    /// The 7 values: diffuse RGB, specular RGB, roughness (the order of `deepbrdf-eval`'s
    /// `Attributes::to_array`).
    pub fn to_array(&self) -> [f64; 7] {
        let (d, s) = (self.diffuse, self.specular);
        [d[0], d[1], d[2], s[0], s[1], s[2], self.roughness]
    }
}

impl Material {
    /// The coat's normal transmission in and out, 1 without a coat.
    fn transmission(&self) -> f64 {
        self.coat.map_or(1.0, |c| c.normal_transmission())
    }

    /// The known attributes (module docs).
    pub fn attributes(&self) -> KnownAttributes {
        let t = self.transmission();
        let diffuse = self.diffuse.map_or([0.0; 3], |d| d.albedo().map(|a| a * t));
        let mut specular = self.coat.map_or([0.0; 3], |c| [dielectric_f0(c.eta); 3]);
        // (mean reflectance, alpha) of each specular component.
        let mut components: Vec<(f64, f64)> =
            self.coat.iter().map(|c| (dielectric_f0(c.eta), c.alpha)).collect();
        for lobe in &self.lobes {
            let r = lobe.normal_reflectance().map(|v| v * t);
            (0..3).for_each(|c| specular[c] += r[c]);
            components.push((r.iter().sum::<f64>() / 3.0, lobe.alpha));
        }
        let main = components.iter().fold(None::<(f64, f64)>, |best, &c| match best {
            Some(b) if b.0 >= c.0 => Some(b),
            _ => Some(c),
        });
        KnownAttributes {
            diffuse,
            specular: specular.map(|v| v.min(1.0)),
            roughness: main.map_or(ALPHA_RANGE.1, |m| m.1),
        }
    }

    /// Every microfacet alpha (lobes and coat) times `s`, clamped to [`ALPHA_RANGE`].
    pub fn roughness_scaled(&self, s: f64) -> Material {
        let scale = |a: f64| (a * s).clamp(ALPHA_RANGE.0, ALPHA_RANGE.1);
        let mut m = self.clone();
        m.lobes.iter_mut().for_each(|l| l.alpha = scale(l.alpha));
        if let Some(c) = &mut m.coat {
            c.alpha = scale(c.alpha);
        }
        m
    }

    /// The diffuse base's albedo times `s`, clamped to [0, 1].
    pub fn diffuse_scaled(&self, s: f64) -> Material {
        let mut m = self.clone();
        m.diffuse = m.diffuse.map(|d| d.with_albedo(d.albedo().map(|a| (a * s).clamp(0.0, 1.0))));
        m
    }

    /// Every specular component's normal-incidence reflectance times `s`: a dielectric's (and
    /// the coat's) index is the one with `s` times its F0 ([`eta_of_f0`]), a Schlick F0 and a
    /// conductor's tint are scaled (all clamped to their ranges). A change of the coat's
    /// transmission is compensated in the base and the lobes under it, so the diffuse attribute
    /// and the specular one's split stay as they were.
    pub fn specular_scaled(&self, s: f64) -> Material {
        let mut m = self.clone();
        let t = self.transmission();
        if let Some(c) = &mut m.coat {
            c.eta = scaled_eta(c.eta, s);
        }
        let compensation = t / m.transmission();
        for lobe in &mut m.lobes {
            let factor = s * compensation;
            match &mut lobe.fresnel {
                Fresnel::Schlick { f0 } => *f0 = f0.map(|f| (f * factor).clamp(0.0, 1.0)),
                Fresnel::Dielectric { eta } => *eta = scaled_eta(*eta, factor),
                Fresnel::Conductor { .. } => {
                    lobe.tint = lobe.tint.map(|v| (v * factor).clamp(0.0, 1.0))
                }
            }
        }
        m.diffuse = m
            .diffuse
            .map(|d| d.with_albedo(d.albedo().map(|a| (a * compensation).clamp(0.0, 1.0))));
        m
    }

    /// The diffuse attribute set to `rgb` (each clamped to [0, 1]): the base's albedo becomes
    /// `rgb` over the coat's transmission; a material without a base gets a Lambertian one.
    pub fn recoloured(&self, rgb: [f64; 3]) -> Material {
        let t = self.transmission();
        let albedo = rgb.map(|v| (v.clamp(0.0, 1.0) / t).clamp(0.0, 1.0));
        let mut m = self.clone();
        m.diffuse = Some(match m.diffuse {
            Some(d) => d.with_albedo(albedo),
            None => Diffuse::Lambertian { albedo },
        });
        m
    }
}

/// The dielectric index whose F0 is `s` times that of `eta`, clamped to
/// [`DIELECTRIC_ETA_RANGE`].
fn scaled_eta(eta: f64, s: f64) -> f64 {
    eta_of_f0(dielectric_f0(eta) * s).clamp(DIELECTRIC_ETA_RANGE.0, DIELECTRIC_ETA_RANGE.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::material::Family;
    use crate::corpus::sampler::sample_family;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * y.abs().max(1e-3))
    }

    #[test]
    fn attributes_of_a_plastic_are_its_parameters() {
        let m = sample_family(Family::Plastic, 1, 0);
        let a = m.attributes();
        let albedo = m.diffuse.map(|d| d.albedo()).unwrap_or_default();
        assert_eq!(a.diffuse, albedo);
        assert_eq!(a.roughness, m.lobes[0].alpha);
        assert_eq!(a.specular, m.lobes[0].normal_reflectance());
    }

    #[test]
    fn edits_reach_their_known_answers() {
        for family in Family::ALL {
            for index in 0..20 {
                let m = sample_family(family, 7, index);
                let a = m.attributes();
                for s in [0.5, 2.0] {
                    let r = m.roughness_scaled(s).attributes();
                    // Without a specular component there is no lobe to widen.
                    let expected = match m.lobes.is_empty() && m.coat.is_none() {
                        true => a.roughness,
                        false => (a.roughness * s).clamp(ALPHA_RANGE.0, ALPHA_RANGE.1),
                    };
                    assert_eq!(r.roughness, expected, "{family} {index} x{s}: {r:?} from {a:?}");
                    assert_eq!((r.diffuse, r.specular), (a.diffuse, a.specular));
                }
                let d = m.diffuse_scaled(0.5).attributes();
                let half = a.diffuse.map(|v| v * 0.5);
                assert!(close(&d.diffuse, &half, 1e-12), "{family}: {d:?} {a:?}");
                assert_eq!((d.specular, d.roughness), (a.specular, a.roughness));
                let s = m.specular_scaled(0.5).attributes();
                let half = a.specular.map(|v| v * 0.5);
                assert!(close(&s.specular, &half, 1e-9), "{family} {index}: {s:?} {a:?}");
                assert!(close(&s.diffuse, &a.diffuse, 1e-9), "{family} {index}: {s:?} {a:?}");
                assert_eq!(s.roughness, a.roughness, "{family} {index}");
                let c = m.recoloured([0.1, 0.6, 0.3]);
                assert!(close(&c.attributes().diffuse, &[0.1, 0.6, 0.3], 1e-12), "{family}");
                for edited in
                    [m.roughness_scaled(2.0), m.diffuse_scaled(0.5), m.specular_scaled(0.5), c]
                {
                    edited.validate().expect("an edit stays valid");
                }
            }
        }
    }

    #[test]
    fn edits_clamp_to_the_valid_ranges() {
        let m = sample_family(Family::Plastic, 3, 4);
        assert_eq!(m.roughness_scaled(1e6).attributes().roughness, ALPHA_RANGE.1);
        assert!(m.diffuse_scaled(1e6).attributes().diffuse.iter().all(|&v| v == 1.0 || v == 0.0));
        m.specular_scaled(1e6).validate().expect("clamped");
        assert_eq!(m.specular_scaled(0.0).attributes().specular, [0.0; 3]);
    }
}

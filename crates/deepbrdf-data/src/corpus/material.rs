//! A material of the corpus: a physically based analytic BRDF described by its parameters, a
//! diffuse base, up to [`MAX_LOBES`] microfacet lobes, sheen, a retro-reflective lobe and a clear
//! coat over all of them: `f = coat(diffuse + lobes + sheen + retro)` ([`Coat::eval`]), or the
//! plain sum without a coat. Serialised with serde (the corpus file's records).

use super::coat::Coat;
use super::diffuse::Diffuse;
use super::fresnel::Fresnel;
use super::microfacet::Lobe;
use super::retro::Retro;
use super::sheen::Sheen;
use crate::error::{DataError, Result};
use serde::{Deserialize, Serialize};

/// Most microfacet lobes under the coat.
pub const MAX_LOBES: usize = 2;
/// Range of microfacet roughness alpha (the attribute model's roughness range: below 1e-3 the
/// MERL grid does not resolve the lobe).
pub const ALPHA_RANGE: (f64, f64) = (1e-3, 1.0);
/// Range of a dielectric's (and the coat's) index: 1 (no interface) to 4 (F0 0.36).
pub const DIELECTRIC_ETA_RANGE: (f64, f64) = (1.0, 4.0);
/// Range of a conductor's real index and extinction coefficient (the IOR table lies within).
pub const CONDUCTOR_ETA_RANGE: (f64, f64) = (0.01, 10.0);
pub const CONDUCTOR_K_RANGE: (f64, f64) = (0.0, 20.0);
/// Range of Oren-Nayar's sigma (radians).
pub const SIGMA_RANGE: (f64, f64) = (0.0, 1.5);
/// Range of the Charlie sheen roughness.
pub const SHEEN_ROUGHNESS_RANGE: (f64, f64) = (0.05, 1.0);
/// Range of the retro-reflective lobe's exponent.
pub const RETRO_EXPONENT_RANGE: (f64, f64) = (1.0, 10_000.0);

/// The family a material was drawn from (see [`super::sampler`]); a label, not used by `eval`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// A diffuse base under one dielectric lobe.
    Plastic,
    /// A (tinted) conductor lobe from a measured complex index.
    Metal,
    /// Oren-Nayar alone.
    RoughDiffuse,
    /// A rough diffuse base with sheen.
    Fabric,
    /// A base with a metallic-flake lobe under a clear coat.
    CoatedPaint,
    /// A diffuse base under a sharp and a wide lobe.
    TwoLobe,
    /// A diffuse base with a retro-reflective lobe.
    RetroReflective,
}

impl Family {
    /// Every family, in the sampler's order.
    pub const ALL: [Family; 7] = [
        Family::Plastic,
        Family::Metal,
        Family::RoughDiffuse,
        Family::Fabric,
        Family::CoatedPaint,
        Family::TwoLobe,
        Family::RetroReflective,
    ];

    /// The kebab-case name (`coated-paint`), as serialised.
    pub fn name(self) -> &'static str {
        match self {
            Family::Plastic => "plastic",
            Family::Metal => "metal",
            Family::RoughDiffuse => "rough-diffuse",
            Family::Fabric => "fabric",
            Family::CoatedPaint => "coated-paint",
            Family::TwoLobe => "two-lobe",
            Family::RetroReflective => "retro-reflective",
        }
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An analytic material with all its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub family: Family,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<Diffuse>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lobes: Vec<Lobe>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sheen: Option<Sheen>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retro: Option<Retro>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coat: Option<Coat>,
}

impl Material {
    /// The BRDF (1/sr) at unit directions (wi, wo), z = normal; 0 below the horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        let mut f = self.diffuse.map_or([0.0; 3], |d| d.eval(wi, wo));
        let mut add = |v: [f64; 3]| (0..3).for_each(|c| f[c] += v[c]);
        self.lobes.iter().for_each(|l| add(l.eval(wi, wo)));
        if let Some(s) = &self.sheen {
            add(s.eval(wi, wo));
        }
        if let Some(r) = &self.retro {
            add(r.eval(wi, wo));
        }
        match &self.coat {
            Some(coat) => coat.eval(f, wi, wo),
            None => f,
        }
    }

    /// The material with every weight multiplied by `k` (in [0, 1]): the base's albedo, the
    /// lobes' tints, the sheen's and the retro-reflective lobe's colours; shapes, indices and
    /// the coat stay.
    pub fn scaled(&self, k: f64) -> Material {
        let times = |v: [f64; 3]| v.map(|x| x * k);
        Material {
            diffuse: self.diffuse.map(|d| d.with_albedo(times(d.albedo()))),
            lobes: self.lobes.iter().map(|l| Lobe { tint: times(l.tint), ..*l }).collect(),
            sheen: self.sheen.map(|s| Sheen { colour: times(s.colour), ..s }),
            retro: self.retro.map(|r| Retro { colour: times(r.colour), ..r }),
            ..self.clone()
        }
    }

    /// Checks every parameter against its range; the error names the field.
    pub fn validate(&self) -> Result<()> {
        let nothing = self.diffuse.is_none()
            && self.lobes.is_empty()
            && self.sheen.is_none()
            && self.retro.is_none();
        if nothing {
            return Err(DataError::Invalid(
                "a material needs a base, a lobe, sheen or retro-reflection".into(),
            ));
        }
        if self.lobes.len() > MAX_LOBES {
            return Err(DataError::Invalid(format!(
                "{} lobes, at most {MAX_LOBES}",
                self.lobes.len()
            )));
        }
        if let Some(d) = &self.diffuse {
            unit_rgb("diffuse.albedo", d.albedo())?;
            if let Diffuse::OrenNayar { sigma, .. } = d {
                within("diffuse.sigma", *sigma, SIGMA_RANGE)?;
            }
        }
        for (i, lobe) in self.lobes.iter().enumerate() {
            within(&format!("lobes[{i}].alpha"), lobe.alpha, ALPHA_RANGE)?;
            unit_rgb(&format!("lobes[{i}].tint"), lobe.tint)?;
            match lobe.fresnel {
                Fresnel::Schlick { f0 } => unit_rgb(&format!("lobes[{i}].fresnel.f0"), f0)?,
                Fresnel::Dielectric { eta } => {
                    within(&format!("lobes[{i}].fresnel.eta"), eta, DIELECTRIC_ETA_RANGE)?
                }
                Fresnel::Conductor { eta, k } => {
                    for c in 0..3 {
                        within(
                            &format!("lobes[{i}].fresnel.eta[{c}]"),
                            eta[c],
                            CONDUCTOR_ETA_RANGE,
                        )?;
                        within(&format!("lobes[{i}].fresnel.k[{c}]"), k[c], CONDUCTOR_K_RANGE)?;
                    }
                }
            }
        }
        if let Some(s) = &self.sheen {
            unit_rgb("sheen.colour", s.colour)?;
            within("sheen.roughness", s.roughness, SHEEN_ROUGHNESS_RANGE)?;
        }
        if let Some(r) = &self.retro {
            unit_rgb("retro.colour", r.colour)?;
            within("retro.exponent", r.exponent, RETRO_EXPONENT_RANGE)?;
        }
        if let Some(c) = &self.coat {
            within("coat.eta", c.eta, DIELECTRIC_ETA_RANGE)?;
            within("coat.alpha", c.alpha, ALPHA_RANGE)?;
        }
        Ok(())
    }
}

/// Checks `lo <= v <= hi` (and finite).
fn within(name: &str, v: f64, (lo, hi): (f64, f64)) -> Result<()> {
    match v.is_finite() && (lo..=hi).contains(&v) {
        true => Ok(()),
        false => Err(DataError::Invalid(format!("{name} = {v} is outside [{lo}, {hi}]"))),
    }
}

/// Checks each channel is in [0, 1].
fn unit_rgb(name: &str, rgb: [f64; 3]) -> Result<()> {
    (0..3).try_for_each(|c| within(&format!("{name}[{c}]"), rgb[c], (0.0, 1.0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::{assert_reciprocal, directional_albedo};
    use crate::corpus::microfacet::Distribution;
    use crate::merl::coords::direction;

    fn paint() -> Material {
        Material {
            family: Family::CoatedPaint,
            diffuse: Some(Diffuse::Lambertian { albedo: [0.3, 0.1, 0.1] }),
            lobes: vec![Lobe {
                distribution: Distribution::Beckmann,
                alpha: 0.3,
                fresnel: Fresnel::Conductor { eta: [0.18, 0.46, 1.37], k: [3.07, 2.41, 1.83] },
                tint: [0.4; 3],
            }],
            sheen: Some(Sheen { colour: [0.2; 3], roughness: 0.4 }),
            retro: Some(Retro { colour: [0.1; 3], exponent: 10.0 }),
            coat: Some(Coat { eta: 1.5, alpha: 0.02 }),
        }
    }

    #[test]
    fn eval_is_the_coated_sum_of_the_parts() {
        let m = paint();
        m.validate().expect("valid");
        let (a, b) = (direction(0.4, 0.1), direction(1.0, 2.5));
        let parts = [
            m.diffuse.as_ref().map(|d| d.eval(a, b)).unwrap_or_default(),
            m.lobes[0].eval(a, b),
            m.sheen.as_ref().map(|s| s.eval(a, b)).unwrap_or_default(),
            m.retro.as_ref().map(|r| r.eval(a, b)).unwrap_or_default(),
        ];
        let base: [f64; 3] = std::array::from_fn(|c| parts.iter().map(|p| p[c]).sum());
        let expected = m.coat.as_ref().map(|coat| coat.eval(base, a, b)).unwrap_or_default();
        let got = m.eval(a, b);
        for c in 0..3 {
            assert!((got[c] - expected[c]).abs() < 1e-12 * expected[c].max(1.0));
        }
        assert_reciprocal(|x, y| m.eval(x, y));
        let albedo = directional_albedo(|x, y| m.eval(x, y), 0.5, 300);
        assert!(albedo.iter().all(|&v| v > 0.0 && v < 1.0), "{albedo:?}");
        assert_eq!(m.eval(a, direction(1.7, 0.0)), [0.0; 3]);
    }

    #[test]
    fn serde_round_trips_and_validate_names_the_field() {
        let m = paint();
        let json = serde_json::to_string(&m).expect("serialise");
        assert_eq!(serde_json::from_str::<Material>(&json).expect("parse"), m);
        assert!(json.contains("\"coated-paint\"") && json.contains("\"beckmann\""), "{json}");
        let mut bad = m.clone();
        bad.lobes[0].alpha = 0.0;
        assert!(bad.validate().expect_err("invalid").to_string().contains("lobes[0].alpha = 0"));
        let mut bad = m.clone();
        bad.diffuse = Some(Diffuse::OrenNayar { albedo: [0.5, f64::NAN, 0.5], sigma: 0.1 });
        assert!(bad
            .validate()
            .expect_err("invalid")
            .to_string()
            .contains("diffuse.albedo[1] = NaN"));
        let mut bad = m.clone();
        bad.lobes = vec![m.lobes[0]; 3];
        assert!(bad.validate().expect_err("invalid").to_string().contains("3 lobes"));
        let empty = Material {
            family: Family::Plastic,
            diffuse: None,
            lobes: vec![],
            sheen: None,
            retro: None,
            coat: m.coat,
        };
        assert!(empty.validate().is_err());
        assert!(serde_json::from_str::<Material>(r#"{"family":"metal","extra":1}"#).is_err());
    }
}

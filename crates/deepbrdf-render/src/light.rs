//! Lights: directional lights (irradiance from one direction, sampled exactly) and environment
//! lights (radiance from every direction: a constant one for the white-furnace test, or the
//! procedural sun and sky of [`super::sky`]).

use super::brdf::{cosine_hemisphere_pdf, sample_cosine_hemisphere, Rgb};
use super::geometry::{Frame, Vec3};
use super::sky::{SunSky, SunSkyConfig};
use crate::error::{RenderError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// Light arriving from a single direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction towards the light (world, z up).
    pub direction: Vec3,
    /// Irradiance on a surface facing the light, per channel.
    pub irradiance: Rgb,
}

/// Most light-sampling strategies an environment has (see [`Environment::strategies`]).
pub const MAX_STRATEGIES: usize = 2;

/// Radiance arriving from all directions.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction (the white furnace).
    Constant(Rgb),
    /// Preetham sun and sky (boxed: it carries its tabulated map).
    SunSky(Box<SunSky>),
}

impl Environment {
    /// Radiance arriving from unit direction `dir`.
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        match self {
            Self::Constant(l) => *l,
            Self::SunSky(s) => s.radiance(dir),
        }
    }

    /// Draws a direction from `u` uniform in [0,1)^2: `(direction, radiance, solid-angle pdf)`.
    /// The constant environment is sampled uniformly over the sphere.
    #[inline]
    pub fn sample(&self, u: [f64; 2]) -> (Vec3, Rgb, f64) {
        match self {
            Self::Constant(l) => {
                let z = 1.0 - 2.0 * u[0];
                let r = (1.0 - z * z).max(0.0).sqrt();
                let (s, c) = (2.0 * PI * u[1]).sin_cos();
                (Vec3::new(r * c, r * s, z), *l, 1.0 / (4.0 * PI))
            }
            Self::SunSky(s) => s.sample(u),
        }
    }

    /// How many light-sampling strategies the renderer gives one sample each at every shading
    /// point: the sun and sky two (the sun's cone, the sky's map), the constant environment none.
    /// Under constant radiance the integrand is `L f cos`, which the BRDF's own sampling already
    /// follows; its light strategy ([`Environment::sample_at`], cosine-weighted over the point's
    /// upper hemisphere) is then the worse of the two: measured on MERL and RGL tables, one
    /// table sample alone had a third of the standard deviation of a table sample plus a cosine
    /// sample combined by the power heuristic, at half the cost. Veach's multi-sample model with
    /// no samples for that strategy (Veach 1997, §9.2.1).
    #[inline]
    pub fn strategies(&self) -> usize {
        match self {
            Self::Constant(_) => 0,
            Self::SunSky(_) => 2,
        }
    }

    /// Draws a direction by strategy `i` (< [`Environment::strategies`]) for a shading point with
    /// local frame `frame`, from `u` uniform in [0,1)^2: `(world direction, radiance, densities
    /// of every strategy there)` (see [`Environment::eval_at`]).
    #[inline]
    pub fn sample_at(&self, i: usize, frame: &Frame, u: [f64; 2]) -> (Vec3, Rgb, [f64; 2]) {
        match self {
            Self::Constant(l) => {
                let wi = sample_cosine_hemisphere(u);
                (frame.to_world(wi), *l, [cosine_hemisphere_pdf(wi), 0.0])
            }
            Self::SunSky(s) => {
                let (dir, l, _) = if i == 0 { s.sample_sun(u) } else { s.sample_sky(u) };
                let (_, p_sun, p_sky) = s.eval_parts(dir);
                (dir, l, [p_sun, p_sky])
            }
        }
    }

    /// Radiance from world direction `dir` and the solid-angle densities of the strategies of
    /// [`Environment::sample_at`] there, for a shading point whose normal makes cosine `cos`
    /// with `dir`.
    #[inline]
    pub fn eval_at(&self, dir: Vec3, cos: f64) -> (Rgb, [f64; 2]) {
        match self {
            Self::Constant(l) => (*l, [cosine_hemisphere_pdf(Vec3::new(0.0, 0.0, cos)), 0.0]),
            Self::SunSky(s) => {
                let (l, p_sun, p_sky) = s.eval_parts(dir);
                (l, [p_sun, p_sky])
            }
        }
    }

    /// Whether no light at all arrives from `dir` (a cheap test: below the sky's horizon and
    /// outside the sun).
    #[inline]
    pub fn is_dark(&self, dir: Vec3) -> bool {
        match self {
            Self::Constant(l) => l.iter().all(|&v| v <= 0.0),
            Self::SunSky(s) => dir.z <= 0.0 && !s.in_sun(dir),
        }
    }

    /// Radiance from `dir` and the density of [`Environment::sample`] there, together.
    #[inline]
    pub fn eval(&self, dir: Vec3) -> (Rgb, f64) {
        match self {
            Self::Constant(l) => (*l, 1.0 / (4.0 * PI)),
            Self::SunSky(s) => s.eval(dir),
        }
    }

    /// Solid-angle density of [`Environment::sample`] at `dir`.
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f64 {
        match self {
            Self::Constant(_) => 1.0 / (4.0 * PI),
            Self::SunSky(s) => s.pdf(dir),
        }
    }
}

/// All the light of a scene.
#[derive(Clone, Debug, Default)]
pub struct Lighting {
    pub directional: Vec<DirectionalLight>,
    pub environment: Option<Environment>,
}

/// The lighting choices of the command line, parsed from `sun:ELEV,AZIM[,TURBIDITY]`,
/// `dir:THETA,PHI` or `const[:L]` (angles in degrees).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LightSpec {
    /// Preetham sun and sky; exposure normalised (see [`super::sky`]).
    Sun { elevation_deg: f64, azimuth_deg: f64, turbidity: f64 },
    /// One directional light at polar angle `theta_deg` from the zenith and azimuth `phi_deg`,
    /// irradiance pi (a white Lambertian facing it has radiance 1).
    Directional { theta_deg: f64, phi_deg: f64 },
    /// Constant environment of radiance `radiance`.
    Constant { radiance: f64 },
}

impl Default for LightSpec {
    fn default() -> Self {
        let c = SunSkyConfig::default();
        Self::Sun {
            elevation_deg: c.elevation_deg,
            azimuth_deg: c.azimuth_deg,
            turbidity: c.turbidity,
        }
    }
}

impl LightSpec {
    /// Builds the lighting (tabulating the sky once).
    pub fn build(&self) -> Result<Lighting> {
        Ok(match *self {
            Self::Sun { elevation_deg, azimuth_deg, turbidity } => Lighting {
                directional: Vec::new(),
                environment: Some(Environment::SunSky(Box::new(SunSky::new(SunSkyConfig {
                    elevation_deg,
                    azimuth_deg,
                    turbidity,
                    ..Default::default()
                })?))),
            },
            Self::Directional { theta_deg, phi_deg } => {
                if !(theta_deg.is_finite() && phi_deg.is_finite()) {
                    return Err(RenderError::Invalid(format!(
                        "light direction {self} is not finite"
                    )));
                }
                Lighting {
                    directional: vec![DirectionalLight {
                        direction: Vec3::from_spherical(
                            theta_deg.to_radians(),
                            phi_deg.to_radians(),
                        ),
                        irradiance: [PI; 3],
                    }],
                    environment: None,
                }
            }
            Self::Constant { radiance } => {
                if !(radiance.is_finite() && radiance >= 0.0) {
                    return Err(RenderError::Invalid(format!(
                        "constant radiance {radiance} must be finite and >= 0"
                    )));
                }
                Lighting {
                    directional: Vec::new(),
                    environment: Some(Environment::Constant([radiance; 3])),
                }
            }
        })
    }
}

impl fmt::Display for LightSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sun { elevation_deg, azimuth_deg, turbidity } => {
                write!(f, "sun:{elevation_deg},{azimuth_deg},{turbidity}")
            }
            Self::Directional { theta_deg, phi_deg } => write!(f, "dir:{theta_deg},{phi_deg}"),
            Self::Constant { radiance } => write!(f, "const:{radiance}"),
        }
    }
}

fn parse_numbers(spec: &str, list: &str, min: usize, max: usize) -> Result<Vec<f64>> {
    let values: std::result::Result<Vec<f64>, _> =
        list.split(',').map(|s| s.trim().parse::<f64>()).collect();
    match values {
        Ok(v) if (min..=max).contains(&v.len()) && v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(RenderError::Invalid(format!(
            "light '{spec}': expected {min}{} finite numbers separated by commas",
            if max > min { format!(" to {max}") } else { String::new() }
        ))),
    }
}

impl FromStr for LightSpec {
    type Err = RenderError;
    fn from_str(spec: &str) -> Result<Self> {
        let (kind, rest) = spec.split_once(':').unwrap_or((spec, ""));
        match kind {
            "sun" => {
                let v = parse_numbers(spec, rest, 2, 3)?;
                Ok(Self::Sun {
                    elevation_deg: v[0],
                    azimuth_deg: v[1],
                    turbidity: v.get(2).copied().unwrap_or(SunSkyConfig::default().turbidity),
                })
            }
            "dir" => {
                let v = parse_numbers(spec, rest, 2, 2)?;
                Ok(Self::Directional { theta_deg: v[0], phi_deg: v[1] })
            }
            "const" if rest.is_empty() => Ok(Self::Constant { radiance: 1.0 }),
            "const" => Ok(Self::Constant { radiance: parse_numbers(spec, rest, 1, 1)?[0] }),
            _ => Err(RenderError::Invalid(format!(
                "light '{spec}': expected sun:ELEV,AZIM[,TURBIDITY], dir:THETA,PHI or const[:L]"
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_specs() {
        assert_eq!(
            "sun:30,45".parse::<LightSpec>().unwrap(),
            LightSpec::Sun { elevation_deg: 30.0, azimuth_deg: 45.0, turbidity: 3.0 }
        );
        assert_eq!(
            "dir:10,-20".parse::<LightSpec>().unwrap(),
            LightSpec::Directional { theta_deg: 10.0, phi_deg: -20.0 }
        );
        assert_eq!("const".parse::<LightSpec>().unwrap(), LightSpec::Constant { radiance: 1.0 });
        for s in ["sun:30,45,4", "dir:1,2", "const:2.5"] {
            let spec: LightSpec = s.parse().unwrap();
            assert_eq!(spec.to_string().parse::<LightSpec>().unwrap(), spec);
        }
        for bad in ["sun", "sun:1", "sun:a,b", "dir:1,2,3", "const:x", "lamp:1", "sun:nan,3"] {
            assert!(bad.parse::<LightSpec>().is_err(), "{bad}");
        }
    }

    #[test]
    fn constant_environment_samples_the_sphere_uniformly() {
        let env = Environment::Constant([2.0; 3]);
        let (d, l, p) = env.sample([0.3, 0.7]);
        assert!((d.length() - 1.0).abs() < 1e-12);
        assert_eq!(l, [2.0; 3]);
        assert_eq!(p, env.pdf(d));
    }

    #[test]
    fn constant_environment_is_cosine_sampled_above_a_shading_point() {
        let env = Environment::Constant([2.0; 3]);
        assert_eq!(env.strategies(), 0);
        let frame = Frame::from_normal(Vec3::new(0.3, -0.5, 0.8).normalized());
        for u in [[0.1, 0.2], [0.7, 0.9], [0.99, 0.5]] {
            let (d, l, p) = env.sample_at(0, &frame, u);
            let cos = d.dot(frame.n);
            assert!(cos > 0.0 && (d.length() - 1.0).abs() < 1e-12, "{d:?}");
            assert_eq!(l, [2.0; 3]);
            assert!((p[0] - cos / PI).abs() < 1e-12, "{p:?} vs {}", cos / PI);
            let (l2, p2) = env.eval_at(d, cos);
            assert!(l2 == l && (p2[0] - p[0]).abs() < 1e-12 && p2[1] == 0.0, "{p2:?} vs {p:?}");
        }
        assert_eq!(env.eval_at(Vec3::new(0.0, 0.0, -1.0), -1.0).1, [0.0; 2]);
    }
}

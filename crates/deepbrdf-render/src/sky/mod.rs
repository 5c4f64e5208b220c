//! A procedural sun and sky: the analytic daylight model of Preetham, Shirley and Smits,
//! "A Practical Analytic Model for Daylight" (SIGGRAPH 1999), tabulated once per scene into a
//! lat-long map of the upper hemisphere with a piecewise-constant 2D distribution for importance
//! sampling, plus the sun as a small disk of constant radiance sampled uniformly in its cone.
//!
//! Units: the model's luminances are in kcd/m^2; the whole environment is then scaled so that a
//! white Lambertian surface facing the sun has radiance 1 (unit exposure at every sun position).

use super::brdf::Rgb;
use super::distribution::Distribution2D;
use super::geometry::{Frame, Vec3};
use crate::error::{RenderError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

mod preetham;

pub use preetham::{sun_transmittance, PreethamSky, SOLAR_ILLUMINANCE_KLUX};

/// Parameters of the sun and sky.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunSkyConfig {
    /// Sun elevation above the horizon, degrees, in (0, 90].
    pub elevation_deg: f64,
    /// Sun azimuth, degrees counter-clockwise from +x (towards +y).
    pub azimuth_deg: f64,
    /// Atmospheric turbidity (Preetham 1999, §3): 2 = very clear, 3 = clear, 10 = hazy.
    pub turbidity: f64,
    /// Angular radius of the sun disk, degrees (the real sun: 0.2665).
    pub sun_radius_deg: f64,
    /// Columns (azimuth, 0-360 deg) of the tabulated sky; rows (zenith angle, 0-90 deg) are a
    /// quarter as many, so cells are about square. The default, 256, gives 1.4 degree cells
    /// (256 KB, small enough to stay in cache); the sky is smooth at that scale, and the sun,
    /// the only sharp feature, is not in the map.
    pub map_width: usize,
}

impl Default for SunSkyConfig {
    fn default() -> Self {
        Self {
            elevation_deg: 40.0,
            azimuth_deg: 30.0,
            turbidity: 3.0,
            sun_radius_deg: 0.2665,
            map_width: 256,
        }
    }
}

/// Luminance of linear sRGB (Rec. 709 weights).
#[inline]
pub fn luminance(c: Rgb) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// One cell of the tabulated sky.
#[derive(Clone, Copy, Debug)]
struct SkyCell {
    radiance: [f32; 3],
    /// `pdf(u, v) / (4 pi)`: the sky map's solid-angle density times `v`.
    sky_pdf_v: f32,
}

/// The sun and sky as an environment light, tabulated and ready for importance sampling.
#[derive(Clone, Debug)]
pub struct SunSky {
    config: SunSkyConfig,
    width: usize,
    height: usize,
    /// Per map cell, row-major over (v = sqrt(1 - cos theta), azimuth): scaled sky radiance and
    /// the sky map's sampling density times `v` (divide by `v` for solid angle), precomputed so
    /// one lookup gives both.
    cells: Vec<SkyCell>,
    distribution: Distribution2D,
    sun: Vec3,
    sun_frame: Frame,
    cos_sun_radius: f64,
    sun_solid_angle: f64,
    /// Scaled radiance inside the sun disk.
    sun_radiance: Rgb,
    /// Probability of sampling the sun disk rather than the sky map.
    sun_prob: f64,
}

impl SunSky {
    /// Tabulates the sky of `config` and builds its sampling distribution (once per scene).
    pub fn new(config: SunSkyConfig) -> Result<Self> {
        let c = config;
        if !(c.elevation_deg > 0.0 && c.elevation_deg <= 90.0) {
            return Err(RenderError::Invalid(format!(
                "sun elevation {} deg is outside (0, 90]",
                c.elevation_deg
            )));
        }
        if !(1.7..=10.0).contains(&c.turbidity) {
            return Err(RenderError::Invalid(format!(
                "turbidity {} is outside [1.7, 10], the range of Preetham's fit",
                c.turbidity
            )));
        }
        if !(c.sun_radius_deg > 0.0 && c.sun_radius_deg <= 10.0) || !c.azimuth_deg.is_finite() {
            return Err(RenderError::Invalid(format!(
                "sun radius {} deg must be in (0, 10] and the azimuth finite",
                c.sun_radius_deg
            )));
        }
        if !(8..=8192).contains(&c.map_width) || c.map_width % 4 != 0 {
            return Err(RenderError::Invalid(format!(
                "sky map width {} not in 8..=8192",
                c.map_width
            )));
        }
        let theta_s = (90.0 - c.elevation_deg).to_radians();
        let sun = Vec3::from_spherical(theta_s, c.azimuth_deg.to_radians());
        let sky = PreethamSky::new(sun, c.turbidity);
        let (width, height) = (c.map_width, c.map_width / 4);
        // Rows are uniform in v = sqrt(1 - cos(theta)) (nearly uniform in theta, and free of
        // acos when indexing); the solid angle is dw = dphi dz = 2 v dv dphi.
        let (d_phi, d_v) = (2.0 * PI / width as f64, 1.0 / height as f64);
        let mut map = Vec::with_capacity(width * height);
        let mut weight = Vec::with_capacity(width * height);
        let (mut sky_power, mut sky_facing) = (0.0, 0.0);
        for row in 0..height {
            let (v0, v1) = (row as f64 * d_v, (row + 1) as f64 * d_v);
            let v = 0.5 * (v0 + v1);
            let theta = (1.0 - v * v).clamp(-1.0, 1.0).acos();
            let solid = d_phi * (v1 * v1 - v0 * v0);
            for col in 0..width {
                let dir = Vec3::from_spherical(theta, (col as f64 + 0.5) * d_phi);
                let l = sky.radiance(dir);
                let y = luminance(l);
                map.push(l.map(|v| v as f32));
                weight.push(y * v);
                sky_power += y * solid;
                sky_facing += y * solid * dir.dot(sun).max(0.0);
            }
        }

        let radius = c.sun_radius_deg.to_radians();
        let cos_sun_radius = radius.cos();
        let sun_solid_angle = 2.0 * PI * (1.0 - cos_sun_radius);
        let transmittance = sun_transmittance(theta_s, c.turbidity);
        let sun_rgb = transmittance.map(|t| t * SOLAR_ILLUMINANCE_KLUX / sun_solid_angle);
        let sun_irradiance = luminance(sun_rgb) * sun_solid_angle;

        let scale = PI / (sun_irradiance + sky_facing);
        if !scale.is_finite() || scale <= 0.0 {
            return Err(RenderError::Invalid(format!("sun and sky of {c:?} carry no light")));
        }
        let sun_prob = (sun_irradiance / (sun_irradiance + sky_power)).clamp(0.1, 0.9);
        let distribution = Distribution2D::new(&weight, width, height);
        let cells = map
            .iter()
            .enumerate()
            .map(|(i, rgb)| SkyCell {
                radiance: rgb.map(|x| (f64::from(x) * scale) as f32),
                sky_pdf_v: (distribution.pdf_cell(i % width, i / width) / (4.0 * PI)) as f32,
            })
            .collect();
        Ok(Self {
            config,
            width,
            height,
            cells,
            distribution,
            sun,
            sun_frame: Frame::from_normal(sun),
            cos_sun_radius,
            sun_solid_angle,
            sun_radiance: sun_rgb.map(|v| v * scale),
            sun_prob,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SunSkyConfig {
        &self.config
    }

    /// Unit direction towards the sun's centre.
    pub fn sun_direction(&self) -> Vec3 {
        self.sun
    }

    /// Radiance inside the sun disk (scaled units).
    pub fn sun_radiance(&self) -> Rgb {
        self.sun_radiance
    }

    /// Map cell (col, row) of an upper-hemisphere direction.
    #[inline]
    fn cell(&self, dir: Vec3) -> (usize, usize) {
        let v = (1.0 - dir.z).max(0.0).sqrt();
        let mut phi = dir.y.atan2(dir.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let col = ((phi / (2.0 * PI) * self.width as f64) as usize).min(self.width - 1);
        let row = ((v * self.height as f64) as usize).min(self.height - 1);
        (col, row)
    }

    /// Whether `dir` lies in the sun disk.
    #[inline]
    pub fn in_sun(&self, dir: Vec3) -> bool {
        dir.dot(self.sun) >= self.cos_sun_radius
    }

    /// Sky radiance alone (the tabulated map; zero below the horizon).
    #[inline]
    pub fn sky_radiance(&self, dir: Vec3) -> Rgb {
        if dir.z <= 0.0 {
            return [0.0; 3];
        }
        let (col, row) = self.cell(dir);
        self.cells[row * self.width + col].radiance.map(f64::from)
    }

    /// Radiance arriving from unit direction `dir`: the sky, plus the sun inside its disk.
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        self.eval(dir).0
    }

    /// Solid-angle density of [`SunSky::sample`] at `dir`.
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f64 {
        self.eval(dir).1
    }

    /// Radiance from `dir` and the density of [`SunSky::sample`] there, in one map lookup.
    #[inline]
    pub fn eval(&self, dir: Vec3) -> (Rgb, f64) {
        let (l, p_sun, p_sky) = self.eval_parts(dir);
        (l, self.sun_prob * p_sun + (1.0 - self.sun_prob) * p_sky)
    }

    /// Draws a direction in the sun disk, uniform in its cone: `(direction, radiance,
    /// density 1 / sun solid angle)` (the radiance includes the sky behind the disk).
    #[inline]
    pub fn sample_sun(&self, u: [f64; 2]) -> (Vec3, Rgb, f64) {
        let cos_t = 1.0 - u[0] * (1.0 - self.cos_sun_radius);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (s, c) = (2.0 * PI * u[1]).sin_cos();
        let dir = self.sun_frame.to_world(Vec3::new(sin_t * c, sin_t * s, cos_t));
        (dir, self.eval(dir).0, 1.0 / self.sun_solid_angle)
    }

    /// Draws a direction from the sky map alone, in proportion to luminance: `(direction,
    /// radiance (plus the sun's inside its disk), density of the map alone)`.
    #[inline]
    pub fn sample_sky(&self, u: [f64; 2]) -> (Vec3, Rgb, f64) {
        let (uv, (col, row), _) = self.distribution.sample(u);
        let v = uv[1];
        let z = 1.0 - v * v;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (sp, cp) = (2.0 * PI * uv[0]).sin_cos();
        let dir = Vec3::new(r * cp, r * sp, z);
        // The cell is known: no angle computations, the sky's part read directly.
        let cell = &self.cells[row * self.width + col];
        let p = if v > 0.0 { f64::from(cell.sky_pdf_v) / v } else { 0.0 };
        let mut l = cell.radiance.map(f64::from);
        if self.in_sun(dir) {
            for (a, s) in l.iter_mut().zip(self.sun_radiance) {
                *a += s;
            }
        }
        (dir, l, p)
    }

    /// Radiance from `dir` and the densities of [`SunSky::sample_sun`] and
    /// [`SunSky::sample_sky`] there, in one map lookup.
    #[inline]
    pub fn eval_parts(&self, dir: Vec3) -> (Rgb, f64, f64) {
        let (mut l, mut p_sky, mut p_sun) = ([0.0; 3], 0.0, 0.0);
        if dir.z > 0.0 {
            let (col, row) = self.cell(dir);
            let cell = &self.cells[row * self.width + col];
            let v = (1.0 - dir.z).max(0.0).sqrt();
            l = cell.radiance.map(f64::from);
            if v > 0.0 {
                p_sky = f64::from(cell.sky_pdf_v) / v;
            }
        }
        if self.in_sun(dir) {
            for (a, s) in l.iter_mut().zip(self.sun_radiance) {
                *a += s;
            }
            p_sun = 1.0 / self.sun_solid_angle;
        }
        (l, p_sun, p_sky)
    }

    /// Draws a direction from `u` uniform in [0,1)^2: the sun disk (uniform in its cone) with
    /// probability `sun_prob`, else the sky map in proportion to luminance. Returns the direction,
    /// its radiance and its density ([`SunSky::pdf`]).
    #[inline]
    pub fn sample(&self, u: [f64; 2]) -> (Vec3, Rgb, f64) {
        let dir = if u[0] < self.sun_prob {
            self.sample_sun([u[0] / self.sun_prob, u[1]]).0
        } else {
            self.sample_sky([(u[0] - self.sun_prob) / (1.0 - self.sun_prob), u[1]]).0
        };
        let (l, p) = self.eval(dir);
        (dir, l, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn sky_is_positive_finite_and_brighter_towards_the_sun() {
        for t in [2.0, 3.0, 6.0, 10.0] {
            for elev in [2.0, 15.0, 40.0, 75.0, 90.0] {
                let theta_s = (90.0f64 - elev).to_radians();
                let sun = Vec3::from_spherical(theta_s, 0.0);
                let sky = PreethamSky::new(sun, t);
                // Every direction of the upper hemisphere on a 2-degree grid.
                for i in 0..45 {
                    for j in 0..180 {
                        let d = Vec3::from_spherical(
                            (i as f64 + 0.5).to_radians() * 2.0,
                            (j as f64).to_radians() * 2.0,
                        );
                        let l = sky.radiance(d);
                        assert!(l.iter().all(|v| v.is_finite()), "T {t} elev {elev}: {l:?}");
                        assert!(luminance(l) > 0.0, "T {t} elev {elev} dir {d:?}: {l:?}");
                    }
                }
                // Along the circle of the sun's elevation (or 30 deg for a zenith sun), luminance
                // falls as the azimuth moves away from the sun.
                let theta = if elev > 80.0 { 60f64.to_radians() } else { theta_s };
                let lum: Vec<f64> = [5.0f64, 20.0, 45.0, 80.0]
                    .iter()
                    .map(|a| luminance(sky.radiance(Vec3::from_spherical(theta, a.to_radians()))))
                    .collect();
                if elev <= 80.0 {
                    assert!(lum.windows(2).all(|w| w[0] > w[1]), "T {t} elev {elev}: {lum:?}");
                }
            }
        }
    }

    #[test]
    fn sun_outshines_the_sky_and_reddens_when_low() {
        let high = SunSky::new(SunSkyConfig { elevation_deg: 60.0, ..Default::default() }).unwrap();
        let low = SunSky::new(SunSkyConfig { elevation_deg: 5.0, ..Default::default() }).unwrap();
        let zenith = high.radiance(Vec3::new(0.0, 0.0, 1.0));
        assert!(luminance(high.sun_radiance()) > 1000.0 * luminance(zenith));
        let ratio = |c: Rgb| c[2] / c[0];
        assert!(ratio(low.sun_radiance()) < ratio(high.sun_radiance()));
    }

    #[test]
    fn exposure_normalisation() {
        // A white Lambertian facing the sun has radiance 1: irradiance pi, by quadrature over
        // directions of the (unnormalised) pieces in the constructor; here checked by Monte Carlo
        // with the sampling density.
        let sky = SunSky::new(SunSkyConfig::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 200_000;
        let mut e = 0.0;
        for _ in 0..n {
            let (d, l, p) = sky.sample([rng.random(), rng.random()]);
            e += luminance(l) * d.dot(sky.sun_direction()).max(0.0) / p;
        }
        let radiance = e / n as f64 / PI;
        assert!((radiance - 1.0).abs() < 0.02, "{radiance}");
    }

    #[test]
    fn sampling_density_matches_pdf_and_integrates_to_one() {
        let sky = SunSky::new(SunSkyConfig { sun_radius_deg: 10.0, ..Default::default() }).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..2000 {
            let (d, l, p) = sky.sample([rng.random(), rng.random()]);
            assert!((d.length() - 1.0).abs() < 1e-9);
            assert!((p - sky.pdf(d)).abs() <= 1e-9 * p);
            assert_eq!(l, sky.radiance(d));
        }
        // Integral of the pdf over the sphere = 1: stratified uniform-sphere Monte Carlo
        // (uniform in z = cos(theta) and phi is uniform in solid angle).
        let (nz, nphi) = (800, 500);
        let mut total = 0.0;
        for i in 0..nz {
            for j in 0..nphi {
                let z = -1.0 + 2.0 * (i as f64 + rng.random::<f64>()) / nz as f64;
                let phi = 2.0 * PI * (j as f64 + rng.random::<f64>()) / nphi as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                total += sky.pdf(Vec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        let total = total * 4.0 * PI / (nz * nphi) as f64;
        assert!((total - 1.0).abs() < 0.01, "{total}");
    }

    #[test]
    fn sun_and_sky_strategies_match_their_densities() {
        let sky = SunSky::new(SunSkyConfig { sun_radius_deg: 5.0, ..Default::default() }).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let n = 100_000;
        // E[L / p] over each strategy's samples estimates the integral of the luminance over its
        // support: the sun strategy's covers the disk, the sky map's the upper hemisphere.
        let (mut disk, mut hemisphere) = (0.0, 0.0);
        for _ in 0..n {
            let (d, l, p) = sky.sample_sun([rng.random(), rng.random()]);
            let (l2, p_sun, _) = sky.eval_parts(d);
            assert!(sky.in_sun(d) && l == l2 && (p - p_sun).abs() <= 1e-12 * p);
            disk += luminance(l) / p;
            let (d, l, p) = sky.sample_sky([rng.random(), rng.random()]);
            let (l2, _, p_sky) = sky.eval_parts(d);
            assert!(d.z >= 0.0 && l == l2 && (p - p_sky).abs() <= 1e-6 * p, "{p} {p_sky}");
            hemisphere += luminance(sky.sky_radiance(d)) / p;
        }
        // Reference: stratified uniform sampling of the upper hemisphere.
        let (mut ref_disk, mut ref_hemisphere) = (0.0, 0.0);
        let (nz, nphi) = (1000, 1000);
        for i in 0..nz {
            for j in 0..nphi {
                let z = (i as f64 + rng.random::<f64>()) / nz as f64;
                let phi = 2.0 * PI * (j as f64 + rng.random::<f64>()) / nphi as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                let cell = 2.0 * PI / (nz * nphi) as f64;
                ref_hemisphere += luminance(sky.sky_radiance(d)) * cell;
                if sky.in_sun(d) {
                    ref_disk += luminance(sky.radiance(d)) * cell;
                }
            }
        }
        let (disk, hemisphere) = (disk / n as f64, hemisphere / n as f64);
        assert!((disk / ref_disk - 1.0).abs() < 0.02, "{disk} vs {ref_disk}");
        assert!(
            (hemisphere / ref_hemisphere - 1.0).abs() < 0.02,
            "{hemisphere} vs {ref_hemisphere}"
        );
    }

    #[test]
    fn rejects_bad_parameters() {
        for c in [
            SunSkyConfig { elevation_deg: -5.0, ..Default::default() },
            SunSkyConfig { turbidity: 50.0, ..Default::default() },
            SunSkyConfig { sun_radius_deg: f64::NAN, ..Default::default() },
            SunSkyConfig { map_width: 1 << 30, ..Default::default() },
        ] {
            assert!(SunSky::new(c).is_err(), "{c:?}");
        }
    }
}

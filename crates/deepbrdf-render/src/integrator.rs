//! The renderer: direct illumination of one shape, rayon-parallel over rows, deterministic for a
//! seed (every pixel draws from its own ChaCha8 stream, so the image does not depend on thread
//! scheduling).
//!
//! Per sample: a (jittered) camera ray; at its hit, the exact contribution of every directional
//! light, and the environment by multiple importance sampling with both strategies at every
//! shading point (Veach 1997, §9.2, the multi-sample model with the power heuristic, beta = 2):
//! one direction per light strategy of the environment
//! ([`crate::light::Environment::sample_at`]: the sun's cone and the sky's map) and one from the
//! BRDF's. Light sampling finds the sun, BRDF sampling finds mirror reflections, and the
//! heuristic keeps each where it is better. The constant environment has no light strategy of
//! its own (see [`crate::light::Environment::strategies`]): BRDF sampling alone follows its
//! integrand.

use super::brdf::{Brdf, Rgb};
use super::geometry::{Frame, Vec3};
use super::image::{Image, MAX_SIZE};
use super::light::MAX_STRATEGIES;
use super::sampler::{PixelSampler, Sampler, MAX_SOBOL_SAMPLES};
use super::scene::Scene;
use crate::error::{RenderError, Result};
use deepbrdf_data::Progress;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Largest sample count per pixel accepted.
pub const MAX_SPP: u32 = MAX_SOBOL_SAMPLES;

/// How to render: image size, samples per pixel, seed, pixel sampling and sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RenderSettings {
    /// Image width and height in pixels.
    pub size: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of every random choice.
    pub seed: u64,
    /// Jitter samples over the pixel (anti-aliased edges); `false` shades pixel centres only.
    pub jitter: bool,
    /// Where the random numbers come from ([`Sampler`]); settings stored before there was a
    /// choice read as the independent sampler they were rendered with.
    #[serde(default = "Sampler::stored_default")]
    pub sampler: Sampler,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { size: 256, spp: 64, seed: 0, jitter: true, sampler: Sampler::Sobol }
    }
}

impl RenderSettings {
    /// Checks the settings are in range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SIZE).contains(&self.size) || !(1..=MAX_SPP).contains(&self.spp) {
            return Err(RenderError::Invalid(format!(
                "image size {} must be in 1..={MAX_SIZE} and samples per pixel {} in 1..={MAX_SPP}",
                self.size, self.spp
            )));
        }
        Ok(())
    }
}

/// Renders `brdf` on `scene`. Pixels the shape does not cover are black; the image's coverage
/// channel says which fraction of each pixel's samples hit the shape.
pub fn render(
    scene: &Scene,
    brdf: &dyn Brdf,
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> Result<Image> {
    settings.validate()?;
    let n = settings.size as usize;
    let mut image = Image::black(settings.size, settings.size);
    progress.start(n as u64, "render");
    let (rgb, coverage) = image.buffers_mut();
    rgb.par_chunks_mut(n).zip(coverage.par_chunks_mut(n)).enumerate().for_each(
        |(y, (row, cov))| {
            for (x, (px, c)) in row.iter_mut().zip(cov.iter_mut()).enumerate() {
                let mut sampler =
                    PixelSampler::new(settings.sampler, settings.seed, (y * n + x) as u64);
                let (l, hits) = render_pixel(scene, brdf, settings, x, y, &mut sampler);
                let inv = 1.0 / f64::from(settings.spp);
                *px = l.map(|v| (v * inv) as f32);
                *c = (hits as f64 * inv) as f32;
            }
            progress.advance(1);
        },
    );
    progress.finish();
    Ok(image)
}

/// Sum over the pixel's samples of radiance, and the number of samples that hit the shape.
#[inline]
fn render_pixel(
    scene: &Scene,
    brdf: &dyn Brdf,
    settings: &RenderSettings,
    x: usize,
    y: usize,
    sampler: &mut PixelSampler,
) -> (Rgb, u32) {
    let n = f64::from(settings.size);
    let mut sum = [0.0; 3];
    let mut hits = 0;
    for i in 0..settings.spp {
        let [jx, jy] = if settings.jitter { sampler.pixel_offset(i) } else { [0.5, 0.5] };
        let ray = scene.camera.ray((x as f64 + jx) / n, (y as f64 + jy) / n);
        let Some(hit) = scene.shape.intersect(&ray, 0.0) else {
            continue;
        };
        hits += 1;
        let frame = Frame::from_normal(hit.normal);
        let wo = frame.to_local(-ray.dir);
        if wo.z <= 0.0 {
            continue;
        }
        let l = shade(scene, brdf, &frame, hit.point, wo, (sampler, i));
        for c in 0..3 {
            sum[c] += l[c];
        }
    }
    (sum, hits)
}

/// Reflected radiance towards `wo` (local) at `point`: directional lights exactly, plus the
/// environment estimated by one sample of each light strategy and one BRDF sample, combined by
/// the power heuristic (Veach 1997, eq. 9.13: strategy `i`'s sample weighs `p_i^2 / sum_j p_j^2`,
/// so its contribution is `f L cos p_i / sum_j p_j^2`).
#[inline]
fn shade(
    scene: &Scene,
    brdf: &dyn Brdf,
    frame: &Frame,
    point: Vec3,
    wo: Vec3,
    (sampler, index): (&mut PixelSampler, u32),
) -> Rgb {
    let shape = &scene.shape;
    let mut out = [0.0; 3];
    for light in &scene.lighting.directional {
        let wi = frame.to_local(light.direction);
        if wi.z <= 0.0 || shape.occludes(point, frame.n, light.direction) {
            continue;
        }
        let f = brdf.eval(wi, wo);
        for c in 0..3 {
            out[c] += f[c] * light.irradiance[c] * wi.z;
        }
    }
    let Some(env) = &scene.lighting.environment else {
        return out;
    };
    let mut add = |f: Rgb, radiance: Rgb, w: f64| {
        for c in 0..3 {
            out[c] += f[c] * radiance[c] * w;
        }
    };
    // One sample per light strategy, then one BRDF sample; each weighted by the power
    // heuristic over all strategies' densities at its direction.
    let strategies = env.strategies();
    let u = sampler.shade_point(index, strategies);
    // Only the strategies that draw samples enter the heuristic.
    let sum_sq = |p: &[f64; MAX_STRATEGIES], b: f64| {
        p[..strategies].iter().map(|x| x * x).sum::<f64>() + b * b
    };
    for i in 0..strategies {
        let (dir, radiance, pdfs) = env.sample_at(i, frame, u.light[i]);
        let wi = frame.to_local(dir);
        let p = pdfs[i];
        if !(wi.z > 0.0 && p > 0.0) || radiance.iter().all(|&v| v <= 0.0) {
            continue;
        }
        let f = brdf.eval(wi, wo);
        if f.iter().any(|&v| v > 0.0) && !shape.occludes(point, frame.n, dir) {
            add(f, radiance, p / sum_sq(&pdfs, brdf.pdf(wi, wo)) * wi.z);
        }
    }
    if let Some(wi) = brdf.sample(wo, u.brdf) {
        let dir = frame.to_world(wi);
        if wi.z > 0.0 && !env.is_dark(dir) {
            let f = brdf.eval(wi, wo);
            let p = brdf.pdf(wi, wo);
            if p > 0.0 && f.iter().any(|&v| v > 0.0) {
                let (radiance, pdfs) = env.eval_at(dir, wi.z);
                if !shape.occludes(point, frame.n, dir) {
                    add(f, radiance, p / sum_sq(&pdfs, p) * wi.z);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{Lambertian, Sum};
    use crate::camera::Projection;
    use crate::light::{DirectionalLight, Environment, LightSpec, Lighting};
    use crate::scene::SceneConfig;
    use crate::shape::Shape;
    use deepbrdf_data::Silent;
    use std::f64::consts::PI;

    /// An orthographic view of the unit sphere from +x: image right = +y, image up = +z, the
    /// image spanning +-(1 + 0.04) (see `camera`).
    fn sphere_from_x(lighting: Lighting) -> Scene {
        let mut scene = SceneConfig {
            shape: Shape::Sphere { radius: 1.0 },
            light: LightSpec::Constant { radiance: 0.0 },
            view_theta_deg: 90.0,
            view_phi_deg: 0.0,
            projection: Projection::Orthographic,
        }
        .build()
        .unwrap();
        scene.lighting = lighting;
        scene
    }

    #[test]
    fn lambertian_sphere_under_a_directional_light_is_exact() {
        let rho = [0.8, 0.5, 0.25];
        let e = [2.0, 3.0, 1.5];
        let dir = Vec3::new(0.6, -0.48, 0.64).normalized();
        let scene = sphere_from_x(Lighting {
            directional: vec![DirectionalLight { direction: dir, irradiance: e }],
            environment: None,
        });
        let size = 48;
        let settings =
            RenderSettings { size, spp: 1, seed: 1, jitter: false, sampler: Sampler::Sobol };
        let image = render(&scene, &Lambertian::new(rho), &settings, &Silent).unwrap();
        let half = 1.04;
        let mut lit = 0;
        for py in 0..size {
            for px in 0..size {
                // Independent geometry: the pixel centre's point on the sphere seen from +x.
                let y = (2.0 * (f64::from(px) + 0.5) / f64::from(size) - 1.0) * half;
                let z = (1.0 - 2.0 * (f64::from(py) + 0.5) / f64::from(size)) * half;
                let r2 = y * y + z * z;
                let got = image.get(px, py);
                let cov = image.coverage()[(py * size + px) as usize];
                if r2 >= 1.0 {
                    assert_eq!((got, cov), ([0.0; 3], 0.0), "pixel {px},{py} off the sphere");
                    continue;
                }
                assert_eq!(cov, 1.0);
                let normal = Vec3::new((1.0 - r2).sqrt(), y, z);
                let cos = normal.dot(dir).max(0.0);
                if cos > 0.0 {
                    lit += 1;
                }
                for c in 0..3 {
                    let want = rho[c] / PI * e[c] * cos;
                    // f32 storage: relative precision 2^-24 plus the normal's rounding.
                    assert!(
                        (f64::from(got[c]) - want).abs() <= 1e-6 * want.max(1e-3),
                        "pixel {px},{py} channel {c}: {} vs {want}",
                        got[c]
                    );
                }
            }
        }
        assert!(lit > 500, "{lit} lit pixels");
    }

    /// The green channel of the fully covered pixels of `brdf`'s render under constant radiance
    /// 1.5 (orthographic sphere, pixel centres).
    fn furnace(brdf: &dyn Brdf, spp: u32, seed: u64) -> Vec<f64> {
        let scene = sphere_from_x(Lighting {
            directional: vec![],
            environment: Some(Environment::Constant([1.5; 3])),
        });
        let settings =
            RenderSettings { size: 24, spp, seed, jitter: false, sampler: Sampler::Sobol };
        let image = render(&scene, brdf, &settings, &Silent).unwrap();
        image
            .pixels()
            .iter()
            .zip(image.coverage())
            .filter(|(_, &c)| c == 1.0)
            .map(|(p, _)| f64::from(p[1]))
            .collect()
    }

    #[test]
    fn white_furnace_is_exact_for_a_lambertian() {
        // Albedo 1 under constant radiance L reflects L everywhere. BRDF samples (cosine) give
        // exactly L: every pixel is L up to rounding.
        let values = furnace(&Lambertian::new([1.0; 3]), 4, 11);
        assert!(values.len() > 300, "{} covered pixels", values.len());
        for v in values {
            assert!((v - 1.5).abs() < 1e-5, "{v}");
        }
    }

    #[test]
    fn glossy_furnace_converges_at_the_monte_carlo_rate() {
        // A plastic's reflected radiance is not constant, so the noise is measured between two
        // seeds: the pixel-wise difference's spread must shrink as 1/sqrt(spp), x4 from 4 to 64
        // spp, and its mean stay zero (no seed-dependent bias).
        let brdf = Sum::plastic([0.5, 0.5, 0.5], 0.1, [0.2; 3]);
        let spread = |spp: u32| {
            let (a, b) = (furnace(&brdf, spp, 1), furnace(&brdf, spp, 2));
            let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
            let n = d.len() as f64;
            let mean = d.iter().sum::<f64>() / n;
            let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            assert!(mean.abs() < 4.0 * sd / n.sqrt(), "{spp} spp: mean difference {mean}");
            (sd, a.iter().sum::<f64>() / n)
        };
        let ((s4, m4), (s64, m64)) = (spread(4), spread(64));
        let ratio = s4 / s64;
        // Randomised quasi-Monte Carlo (the default Sobol sampler) converges at least at the
        // Monte Carlo rate (x4); the independent sampler at that rate exactly.
        assert!(ratio >= 3.2, "noise ratio {ratio} (s4 {s4}, s64 {s64})");
        // Energy: below L (absorbed), above the diffuse part's 0.5 L, the same at both counts.
        assert!(m64 > 0.75 && m64 < 1.5 && (m4 - m64).abs() < 0.02, "{m4} {m64}");
        assert!(s64 > 0.0 && s64 < 0.1 * m64, "s64 {s64}");
    }

    #[test]
    fn seed_changes_noise_not_the_mean() {
        let scene = SceneConfig::default().build().unwrap();
        let brdf = Sum::plastic([0.4, 0.3, 0.2], 0.15, [0.04; 3]);
        let settings =
            RenderSettings { size: 32, spp: 16, seed: 1, jitter: true, sampler: Sampler::Sobol };
        let a = render(&scene, &brdf, &settings, &Silent).unwrap();
        let a2 = render(&scene, &brdf, &settings, &Silent).unwrap();
        assert_eq!(a, a2, "same seed, same image");
        let b = render(&scene, &brdf, &RenderSettings { seed: 2, ..settings }, &Silent).unwrap();
        let differing = a.pixels().iter().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert!(differing > 500, "{differing} pixels differ");
        // Means over the image agree within their Monte Carlo error, estimated from the
        // pixel-wise differences (independent across pixels).
        let diffs: Vec<f64> = a
            .pixels()
            .iter()
            .zip(b.pixels())
            .map(|(p, q)| (0..3).map(|c| f64::from(p[c]) - f64::from(q[c])).sum::<f64>())
            .collect();
        let n = diffs.len() as f64;
        let mean_diff = diffs.iter().sum::<f64>() / n;
        let sd = (diffs.iter().map(|d| (d - mean_diff).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(mean_diff.abs() < 4.0 * sd / n.sqrt(), "mean difference {mean_diff}, sd {sd}");
        let mean_a: f64 =
            a.pixels().iter().map(|p| p.iter().map(|&v| f64::from(v)).sum::<f64>()).sum::<f64>()
                / n;
        assert!(mean_a > 0.05, "{mean_a}");
        // The coverage is identical (same jitter pattern is not required, only the same shape).
        let (ca, cb): (f32, f32) = (a.coverage().iter().sum(), b.coverage().iter().sum());
        assert!((ca - cb).abs() / ca < 0.02);
    }

    #[test]
    fn thread_count_does_not_change_the_image() {
        let scene =
            SceneConfig { shape: "torus".parse().unwrap(), ..Default::default() }.build().unwrap();
        let brdf = Lambertian::new([0.5; 3]);
        let settings =
            RenderSettings { size: 16, spp: 4, seed: 5, jitter: true, sampler: Sampler::Sobol };
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let a = one.install(|| render(&scene, &brdf, &settings, &Silent).unwrap());
        let b = render(&scene, &brdf, &settings, &Silent).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn rejects_absurd_settings() {
        let scene = SceneConfig::default().build().unwrap();
        let brdf = Lambertian::new([0.5; 3]);
        for s in [
            RenderSettings { size: 0, ..Default::default() },
            RenderSettings { spp: 0, ..Default::default() },
            RenderSettings { size: MAX_SIZE + 1, ..Default::default() },
        ] {
            assert!(render(&scene, &brdf, &s, &Silent).is_err());
        }
    }
}

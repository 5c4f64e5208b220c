//! Random scenes for the single-image recovery training set (Hu et al. 2020, §5.2: "each image
//! only contains one virtual object captured at different viewpoints ... chosen to cover various
//! shapes of highlights", under sun-and-sky lighting). [`SceneSampler::sample`] draws, for image
//! `index` of a set with seed `seed`, a shape, a viewpoint, a sun position and turbidity, an
//! exposure and a camera-noise level, from the image's own random stream: image `i` is the same
//! whatever else is rendered, in any order, on any number of threads. [`camera_png`] turns a
//! render into the 8-bit image a camera gives (exposure, clipping, sRGB, sensor noise).

use crate::camera::Projection;
use crate::image::{Image, Srgb8Image, Tonemap};
use crate::light::LightSpec;
use crate::scene::SceneConfig;
use crate::shape::Shape;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The ranges scenes are drawn from (uniform unless said otherwise).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneSampler {
    /// Shapes, drawn with equal probability (the renderer's defaults for each name).
    pub shapes: Vec<Shape>,
    /// Camera polar angle from the zenith for curved shapes, degrees.
    pub view_theta_deg: [f64; 2],
    /// Camera polar angle for the plane, degrees (a plane seen near grazing is a thin sliver).
    pub plane_view_theta_deg: [f64; 2],
    /// Sun elevation above the horizon, degrees; the sun's azimuth relative to the camera is
    /// uniform over the full circle (highlights in front, beside and behind the object).
    pub sun_elevation_deg: [f64; 2],
    /// Preetham turbidity (2 very clear, 10 hazy).
    pub turbidity: [f64; 2],
    /// Exposure multiplier before clipping, log-uniform.
    pub exposure: [f64; 2],
    /// Standard deviation of the camera's additive Gaussian noise, in units of the full 8-bit
    /// range (0.01 = 2.55 levels).
    pub noise: [f64; 2],
}

impl Default for SceneSampler {
    /// Every shape of the renderer, views from 20 to 60 degrees above the horizon (planes from
    /// 40 to 80), the sun from 15 to 75 degrees high, turbidity 2 to 6, exposure 0.7 to 1.0 and
    /// noise up to 1% of the range.
    fn default() -> Self {
        Self {
            shapes: crate::shape::SHAPE_NAMES
                .iter()
                .map(|n| n.parse().expect("the shape names parse"))
                .collect(),
            view_theta_deg: [30.0, 70.0],
            plane_view_theta_deg: [10.0, 50.0],
            sun_elevation_deg: [15.0, 75.0],
            turbidity: [2.0, 6.0],
            exposure: [0.7, 1.0],
            noise: [0.0, 0.01],
        }
    }
}

/// One drawn scene: what to render and how to develop it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampledScene {
    pub scene: SceneConfig,
    /// Exposure multiplier of [`camera_png`].
    pub exposure: f32,
    /// Noise standard deviation of [`camera_png`] (fraction of the 8-bit range).
    pub noise: f32,
    /// Seed of the Monte Carlo render and of the noise.
    pub render_seed: u64,
}

impl SceneSampler {
    /// Checks the ranges: at least one shape, each range ordered and inside its domain.
    pub fn validate(&self) -> crate::Result<()> {
        let ok = |r: [f64; 2], lo: f64, hi: f64| {
            r[0].is_finite() && r[1].is_finite() && lo <= r[0] && r[0] <= r[1] && r[1] <= hi
        };
        let checks = [
            ("view theta", ok(self.view_theta_deg, 0.0, 89.0)),
            ("plane view theta", ok(self.plane_view_theta_deg, 0.0, 89.0)),
            ("sun elevation", ok(self.sun_elevation_deg, 1.0, 90.0)),
            ("turbidity", ok(self.turbidity, 1.7, 10.0)),
            ("exposure", ok(self.exposure, 1e-3, 1e3)),
            ("noise", ok(self.noise, 0.0, 0.5)),
        ];
        if let Some((name, _)) = checks.iter().find(|c| !c.1) {
            return Err(crate::RenderError::Invalid(format!("scene sampler: bad {name} range")));
        }
        if self.shapes.is_empty() {
            return Err(crate::RenderError::Invalid("scene sampler: no shape".into()));
        }
        self.shapes.iter().try_for_each(Shape::validate)
    }

    /// The scene of image `index` of a set drawn with `seed` (its own ChaCha8 stream).
    pub fn sample(&self, seed: u64, index: u64) -> SampledScene {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(index);
        let mut uniform = |r: [f64; 2]| r[0] + (r[1] - r[0]) * rng.random::<f64>();
        let shape = self.shapes
            [(uniform([0.0, 1.0]) * self.shapes.len() as f64) as usize % self.shapes.len()];
        let view_range = match shape {
            Shape::Plane { .. } => self.plane_view_theta_deg,
            _ => self.view_theta_deg,
        };
        let view_theta_deg = uniform(view_range);
        let view_phi_deg = uniform([0.0, 360.0]);
        let elevation_deg = uniform(self.sun_elevation_deg);
        let azimuth_deg = (view_phi_deg + uniform([0.0, 360.0])) % 360.0;
        let turbidity = uniform(self.turbidity);
        let (lo, hi) = (self.exposure[0].ln(), self.exposure[1].ln());
        let exposure = uniform([lo, hi]).exp() as f32;
        let noise = uniform(self.noise) as f32;
        let render_seed = rng.random::<u64>();
        SampledScene {
            scene: SceneConfig {
                shape,
                light: LightSpec::Sun { elevation_deg, azimuth_deg, turbidity },
                view_theta_deg,
                view_phi_deg,
                projection: Projection::Orthographic,
            },
            exposure,
            noise,
            render_seed,
        }
    }
}

/// What a camera makes of `image`: radiance times `exposure`, clipped, sRGB-encoded to 8 bits
/// over a black background, plus zero-mean Gaussian noise of standard deviation `noise` (a
/// fraction of the 8-bit range) on every pixel, drawn from `seed`.
pub fn camera_png(image: &Image, exposure: f32, noise: f32, seed: u64) -> Srgb8Image {
    let mut out = image.to_srgb8(&Tonemap { exposure }, [0, 0, 0]);
    if noise > 0.0 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6e6f_6973_65);
        let sd = f64::from(noise) * 255.0;
        for v in &mut out.data {
            // Box-Muller: one standard normal per value.
            let (u1, u2) = (1.0 - rng.random::<f64>(), rng.random::<f64>());
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            *v = (f64::from(*v) + sd * z).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_are_drawn_per_index_within_their_ranges() {
        let sampler = SceneSampler::default();
        sampler.validate().unwrap();
        let a: Vec<SampledScene> = (0..200).map(|i| sampler.sample(7, i)).collect();
        // The same index gives the same scene, whatever was drawn before.
        assert_eq!(sampler.sample(7, 150), a[150]);
        assert_ne!(sampler.sample(8, 150), a[150]);
        let mut shapes = std::collections::BTreeSet::new();
        for s in &a {
            shapes.insert(s.scene.shape.name());
            let LightSpec::Sun { elevation_deg, turbidity, .. } = s.scene.light else {
                panic!("not a sun: {:?}", s.scene.light)
            };
            assert!((15.0..=75.0).contains(&elevation_deg) && (2.0..=6.0).contains(&turbidity));
            let view = match s.scene.shape {
                Shape::Plane { .. } => sampler.plane_view_theta_deg,
                _ => sampler.view_theta_deg,
            };
            assert!((view[0]..=view[1]).contains(&s.scene.view_theta_deg));
            assert!((0.7..=1.0).contains(&s.exposure) && (0.0..=0.01).contains(&s.noise));
            s.scene.build().unwrap();
        }
        assert_eq!(shapes.len(), 5, "{shapes:?}");
        let mut bad = sampler.clone();
        bad.turbidity = [5.0, 3.0];
        assert!(bad.validate().unwrap_err().to_string().contains("turbidity"));
    }

    #[test]
    fn the_camera_adds_seeded_noise_around_the_developed_image() {
        let image = Image::from_pixels(2, 1, vec![[0.2; 3], [2.0; 3]], vec![1.0, 1.0]).unwrap();
        let clean = camera_png(&image, 1.0, 0.0, 1);
        assert_eq!(clean.data, image.to_srgb8(&Tonemap::default(), [0, 0, 0]).data);
        assert_eq!(clean.data[3..], [255; 3]); // clipped
        let noisy = camera_png(&image, 1.0, 0.02, 1);
        assert_eq!(noisy, camera_png(&image, 1.0, 0.02, 1));
        assert_ne!(noisy, camera_png(&image, 1.0, 0.02, 2));
        for (n, c) in noisy.data.iter().zip(&clean.data) {
            assert!((i32::from(*n) - i32::from(*c)).abs() <= 26, "{n} vs {c}"); // 5 sd
        }
    }
}

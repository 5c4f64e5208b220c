//! Image-space error measures between a render and a reference render of the same scene:
//! the paper's RelAE (Figs. 4, 6-9), and RMSE and PSNR of the tonemapped images, plus a
//! false-colour difference image and [`ImageRelae`], the image-space RelAE between an original
//! MERL table and its reconstruction on a fixed scene.

use crate::error::{EvalError, Result};
use deepbrdf_data::{MerlTable, Silent};
use deepbrdf_render::image::false_colour;
use deepbrdf_render::{
    render, Image, MerlBrdf, RenderSettings, Sampler, Scene, SceneConfig, Srgb8Image, Tonemap,
};
use serde::{Deserialize, Serialize};

fn check_same_size(a: &Image, b: &Image) -> Result<()> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(EvalError::Invalid(format!(
            "images differ in size: {}x{} vs {}x{}",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        )));
    }
    Ok(())
}

/// Whether pixel `i` shows the object in either image.
#[inline]
fn on_object(a: &Image, b: &Image, i: usize) -> bool {
    a.coverage()[i] > 0.0 || b.coverage()[i] > 0.0
}

/// Relative absolute error, `sum |I - I_ref| / sum |I_ref|` over the object's pixels (those any
/// sample of either image hit) and the three channels, as the paper measures reconstructions in
/// image space (§4, Fig. 4). Errors if the reference is black there.
pub fn relae(image: &Image, reference: &Image) -> Result<f64> {
    check_same_size(image, reference)?;
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (i, (p, r)) in image.pixels().iter().zip(reference.pixels()).enumerate() {
        if !on_object(image, reference, i) {
            continue;
        }
        for c in 0..3 {
            num += (f64::from(p[c]) - f64::from(r[c])).abs();
            den += f64::from(r[c]).abs();
        }
    }
    if !(den > 0.0) || !num.is_finite() {
        return Err(EvalError::Invalid(format!(
            "RelAE undefined: the reference image is black on the object (sum {den}, error sum {num})"
        )));
    }
    Ok(num / den)
}

/// Root-mean-square difference of the tonemapped, sRGB-encoded images (values in [0, 1]) over
/// all pixels and channels, each composited over black.
pub fn rmse(image: &Image, reference: &Image, tonemap: &Tonemap) -> Result<f64> {
    check_same_size(image, reference)?;
    let mut sum = 0.0f64;
    for (p, r) in image.pixels().iter().zip(reference.pixels()) {
        for c in 0..3 {
            let d = f64::from(tonemap.display(p[c]) - tonemap.display(r[c]));
            sum += d * d;
        }
    }
    Ok((sum / (3 * image.pixels().len()) as f64).sqrt())
}

/// Peak signal-to-noise ratio of the tonemapped images, `20 log10(1 / RMSE)` dB (peak 1);
/// infinite for identical images.
pub fn psnr(image: &Image, reference: &Image, tonemap: &Tonemap) -> Result<f64> {
    let e = rmse(image, reference, tonemap)?;
    Ok(if e > 0.0 { -20.0 * e.log10() } else { f64::INFINITY })
}

/// All three measures of one comparison.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageComparison {
    pub relae: f64,
    pub rmse: f64,
    pub psnr: f64,
}

/// RelAE, RMSE and PSNR of `image` against `reference`.
pub fn compare_images(
    image: &Image,
    reference: &Image,
    tonemap: &Tonemap,
) -> Result<ImageComparison> {
    Ok(ImageComparison {
        relae: relae(image, reference)?,
        rmse: rmse(image, reference, tonemap)?,
        psnr: psnr(image, reference, tonemap)?,
    })
}

/// A false-colour image of the per-pixel absolute error `sum_c |I - I_ref|`, relative to the
/// mean of `sum_c |I_ref|` over the object's pixels: black is no error, bright yellow an error of
/// `scale` times the object's mean brightness or more (inferno colour map). Off-object pixels
/// are dark grey.
pub fn difference_image(image: &Image, reference: &Image, scale: f64) -> Result<Srgb8Image> {
    check_same_size(image, reference)?;
    if !(scale > 0.0 && scale.is_finite()) {
        return Err(EvalError::Invalid(format!("difference scale {scale} must be positive")));
    }
    let sum_abs = |p: &[f32; 3]| p.iter().map(|&v| f64::from(v).abs()).sum::<f64>();
    let (mut total, mut count) = (0.0, 0usize);
    for (i, r) in reference.pixels().iter().enumerate() {
        if on_object(image, reference, i) {
            total += sum_abs(r);
            count += 1;
        }
    }
    let mean = if count > 0 && total > 0.0 { total / count as f64 } else { 1.0 };
    let mut out = Srgb8Image::filled(image.width(), image.height(), [40, 40, 40]);
    for (i, (p, r)) in image.pixels().iter().zip(reference.pixels()).enumerate() {
        if !on_object(image, reference, i) {
            continue;
        }
        let e: f64 = (0..3).map(|c| (f64::from(p[c]) - f64::from(r[c])).abs()).sum();
        out.data[3 * i..3 * i + 3].copy_from_slice(&false_colour((e / mean / scale) as f32));
    }
    Ok(out)
}

/// The fixed scene of [`ImageRelae`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageRelaeConfig {
    pub scene: SceneConfig,
    pub render: RenderSettings,
}

impl Default for ImageRelaeConfig {
    /// The preview sphere under the default sun and sky, 128 x 128 pixels, 16 samples per
    /// pixel, a fixed seed, the independent sampler (the committed results of sweep-k, the
    /// baselines and the editing and recovery suites were measured with it; both renders of a
    /// comparison share their random numbers, so most of the noise cancels in the difference).
    fn default() -> Self {
        Self {
            scene: SceneConfig::default(),
            render: RenderSettings {
                size: 128,
                spp: 16,
                seed: 0x5eed,
                jitter: true,
                sampler: Sampler::Independent,
            },
        }
    }
}

impl ImageRelaeConfig {
    /// A figure's renders: the preview sphere under the default sun and sky, `size` pixels
    /// square, `spp` Owen-scrambled Sobol samples per pixel (less grain than independent ones at
    /// the same count), seeded.
    pub fn figure(size: u32, spp: u32, seed: u64) -> Self {
        Self {
            scene: SceneConfig::default(),
            render: RenderSettings { size, spp, seed, jitter: true, sampler: Sampler::Sobol },
        }
    }

    /// The same settings with the next seed.
    pub fn next_seed(&self) -> Self {
        Self {
            render: RenderSettings { seed: self.render.seed.wrapping_add(1), ..self.render },
            ..*self
        }
    }
}

/// Image-space RelAE of reconstructions of one original table: the original is rendered once;
/// each reconstruction is rendered with the same seed and the original's sampling, so both
/// renders draw the same directions and their difference carries (almost) no Monte Carlo noise,
/// only the difference of the BRDFs.
pub struct ImageRelae {
    scene: Scene,
    config: ImageRelaeConfig,
    sampling: deepbrdf_render::MerlSampling,
    reference: Image,
}

impl ImageRelae {
    /// Renders `original` on the scene of `config`.
    pub fn new(original: &MerlTable, config: &ImageRelaeConfig) -> Result<Self> {
        let scene = config.scene.build()?;
        let brdf = MerlBrdf::new(original);
        let reference = render(&scene, &brdf, &config.render, &Silent)?;
        Ok(Self { scene, config: *config, sampling: brdf.sampling().clone(), reference })
    }

    /// The original's render.
    pub fn reference(&self) -> &Image {
        &self.reference
    }

    /// Renders `reconstruction` like the original.
    pub fn render(&self, reconstruction: &MerlTable) -> Result<Image> {
        let brdf = MerlBrdf::new_sampled(reconstruction, self.sampling.clone());
        Ok(render(&self.scene, &brdf, &self.config.render, &Silent)?)
    }

    /// The renderer's noise at these settings: the image RelAE between the original's render
    /// and one with the next seed; `original` is the table this measure was made with. It bounds
    /// the noise of a figure's tiles; a reconstruction measured here shares the original's
    /// random numbers and carries less.
    pub fn noise(&self, original: &MerlTable) -> Result<f64> {
        let brdf = MerlBrdf::new_sampled(original, self.sampling.clone());
        let other = render(&self.scene, &brdf, &self.config.next_seed().render, &Silent)?;
        relae(&other, &self.reference)
    }

    /// RelAE of `reconstruction`'s render against the original's.
    pub fn measure(&self, reconstruction: &MerlTable) -> Result<f64> {
        relae(&self.render(reconstruction)?, &self.reference)
    }
}

/// Image-space RelAE between renders of `original` and `reconstruction` on the scene of `config`
/// (see [`ImageRelae`]; use it directly to measure many reconstructions of one original).
pub fn image_relae(
    original: &MerlTable,
    reconstruction: &MerlTable,
    config: &ImageRelaeConfig,
) -> Result<f64> {
    ImageRelae::new(original, config)?.measure(reconstruction)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[[f32; 3]], coverage: &[f32]) -> Image {
        Image::from_pixels(2, 2, values.to_vec(), coverage.to_vec()).unwrap()
    }

    #[test]
    fn relae_by_hand() {
        let reference = image(
            &[[1.0, 2.0, 3.0], [4.0, 0.0, 0.0], [9.0, 9.0, 9.0], [0.0; 3]],
            &[1.0, 0.5, 0.0, 0.0],
        );
        let render = image(
            &[[1.5, 2.0, 2.0], [4.0, 1.0, 0.0], [0.0, 0.0, 0.0], [5.0; 3]],
            &[1.0, 0.5, 0.0, 0.0],
        );
        // Object pixels 0 and 1: |0.5| + |1| + |1| = 2.5 over 1 + 2 + 3 + 4 = 10.
        assert!((relae(&render, &reference).unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(relae(&reference, &reference).unwrap(), 0.0);
        let black = image(&[[0.0; 3]; 4], &[1.0; 4]);
        assert!(relae(&render, &black).is_err());
        let big = Image::black(3, 3);
        assert!(relae(&big, &reference).is_err());
    }

    #[test]
    fn rmse_and_psnr_by_hand() {
        let t = Tonemap::default();
        let a = image(&[[1.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]], &[1.0; 4]);
        let b = image(&[[0.0; 3]; 4], &[1.0; 4]);
        // One pixel of four differs by 1 in every channel: RMSE = sqrt(1/4) = 0.5, PSNR 6.02 dB.
        assert!((rmse(&a, &b, &t).unwrap() - 0.5).abs() < 1e-6);
        assert!((psnr(&a, &b, &t).unwrap() - 6.0206).abs() < 1e-3);
        assert_eq!(psnr(&a, &a, &t).unwrap(), f64::INFINITY);
    }

    #[test]
    fn difference_image_marks_errors() {
        let reference = image(&[[1.0; 3], [1.0; 3], [0.0; 3], [0.0; 3]], &[1.0, 1.0, 0.0, 0.0]);
        let render = image(&[[1.0; 3], [2.0; 3], [0.0; 3], [0.0; 3]], &[1.0, 1.0, 0.0, 0.0]);
        let d = difference_image(&render, &reference, 1.0).unwrap();
        assert_eq!(&d.data[0..3], &false_colour(0.0));
        assert_eq!(&d.data[3..6], &false_colour(1.0));
        assert_eq!(&d.data[6..9], &[40, 40, 40]);
    }
}

#[cfg(test)]
mod image_relae_tests {
    use super::*;
    use deepbrdf_data::testing::synthetic_table;

    #[test]
    fn a_figure_s_noise_falls_with_its_samples() {
        let table = synthetic_table(1);
        let noise = |spp| {
            let config = ImageRelaeConfig::figure(32, spp, 3);
            ImageRelae::new(&table, &config).unwrap().noise(&table).unwrap()
        };
        let (coarse, fine) = (noise(1), noise(32));
        assert!(fine > 0.0 && fine < 0.5 * coarse, "noise {fine} at 32 spp vs {coarse} at 1");
        let config = ImageRelaeConfig::figure(32, 4, 7);
        assert_eq!((config.render.sampler, config.next_seed().render.seed), (Sampler::Sobol, 8));
    }

    #[test]
    fn noise_cancels_between_original_and_reconstruction() {
        let original = synthetic_table(2);
        let config = ImageRelaeConfig {
            render: RenderSettings {
                size: 40,
                spp: 4,
                seed: 9,
                jitter: true,
                sampler: Sampler::Sobol,
            },
            ..Default::default()
        };
        let measure = ImageRelae::new(&original, &config).unwrap();
        assert_eq!(measure.measure(&original).unwrap(), 0.0);
        // A uniformly 10% brighter reconstruction: every sample scales by 1.1 exactly (same
        // directions drawn), so RelAE is 0.1 up to float rounding, whatever the noise.
        let mut brighter = original.clone();
        brighter.values_mut().iter_mut().filter(|v| **v >= 0.0).for_each(|v| *v *= 1.1);
        let e = image_relae(&original, &brighter, &config).unwrap();
        assert!((e - 0.1).abs() < 1e-5, "{e}");
    }
}

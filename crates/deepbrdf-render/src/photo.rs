//! The input photograph of single-image recovery (Hu et al. 2020, §5.2, Fig. 15: "a 256x256
//! colour image" of one object): reading a PNG, JPEG or EXR file of any size, separating the
//! object from the background (by the alpha channel where there is one, else as the pixels
//! brighter than a plain dark background), cropping a square around it and resampling it to the
//! network's side. The same steps prepare the rendered training images and a user's photo, so
//! both reach the network alike. Photos it cannot use (blank, saturated, no object, no dark
//! background) are refused with a message that says why, rather than guessed from.

use crate::error::{RenderError, Result};
use crate::image::{linear_to_srgb, Image, Srgb8Image, Tonemap};
use std::path::Path;

/// A display value (sRGB-encoded, in [0, 1]) at or below this, in luminance, is background
/// when there is no alpha channel: 15 of 255 levels, six standard deviations of the render
/// set's strongest camera noise above black.
pub const BACKGROUND_LEVEL: f32 = 15.0 / 255.0;
/// A pixel with every channel at or above this is saturated (clipped by the camera).
const SATURATED_LEVEL: f32 = 254.0 / 255.0;
/// Fewest object pixels, and least fraction of the image, accepted as an object.
const MIN_OBJECT_PIXELS: usize = 32;
const MIN_OBJECT_FRACTION: f64 = 0.002;
/// Without alpha, an object covering more than this fraction leaves no background to see.
const MAX_OBJECT_FRACTION: f64 = 0.97;
/// Most saturated fraction of the object's pixels accepted.
const MAX_SATURATED_FRACTION: f64 = 0.5;
/// Margin of the square crop around the object's bounding box, per side, as a fraction of the
/// box's larger side (the renderer's camera frames its shapes with 4%).
const CROP_MARGIN: f64 = 0.04;
/// Largest image side read: an 8192-pixel square is 0.8 GB as f32 RGB (a 12-megapixel
/// camera photo, 0.14 GB).
pub const MAX_PHOTO_SIDE: u32 = 8192;
/// Largest photo file read.
pub const MAX_PHOTO_BYTES: u64 = 1 << 30;
/// Most memory the PNG/JPEG decoder may allocate (an 8192-pixel square of 16-bit RGBA).
const MAX_DECODE_BYTES: u64 = 8192 * 8192 * 8;
/// The first four bytes of an OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// A decoded photo: display-encoded RGB in [0, 1] and, if the file has one, its alpha.
#[derive(Clone, Debug, PartialEq)]
pub struct Photo {
    width: u32,
    height: u32,
    rgb: Vec<[f32; 3]>,
    alpha: Option<Vec<f32>>,
}

impl Photo {
    /// Reads a PNG or JPEG (8 or 16 bits, with or without alpha; the format from the content)
    /// or an OpenEXR file (linear radiance, clipped to [0, 1] and sRGB-encoded; its alpha, as
    /// the renderer writes coverage).
    pub fn read(path: &Path) -> Result<Self> {
        let len = std::fs::metadata(path)
            .map_err(|e| RenderError::format(path, format!("cannot open: {e}")))?
            .len();
        if len > MAX_PHOTO_BYTES {
            return Err(RenderError::format(
                path,
                format!("{len} bytes: larger than the {MAX_PHOTO_BYTES} bytes a photo may have"),
            ));
        }
        let bytes = std::fs::read(path)
            .map_err(|e| RenderError::format(path, format!("cannot read: {e}")))?;
        Self::from_bytes(&bytes, path)
    }

    /// [`Photo::read`] of a file's bytes; `origin` names the file in errors. OpenEXR is told by
    /// its magic number, PNG and JPEG by theirs; the image's size is checked from its header
    /// before its pixels are decoded, and the decoder's allocations are limited.
    pub fn from_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        if bytes.starts_with(&EXR_MAGIC) {
            return Ok(Self::from_linear(&Image::exr_from_bytes(bytes, origin)?));
        }
        let unreadable = |e: image::ImageError| {
            RenderError::format(origin, format!("not a readable PNG, JPEG or EXR image: {e}"))
        };
        let reader = || {
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(MAX_PHOTO_SIDE);
            limits.max_image_height = Some(MAX_PHOTO_SIDE);
            limits.max_alloc = Some(MAX_DECODE_BYTES);
            let mut r = image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| RenderError::format(origin, format!("cannot read: {e}")))?;
            r.limits(limits);
            Ok::<_, RenderError>(r)
        };
        let (w, h) = reader()?.into_dimensions().map_err(unreadable)?;
        check_size(origin, w, h)?;
        let decoded = reader()?.decode().map_err(unreadable)?;
        let has_alpha = decoded.color().has_alpha();
        let rgba = decoded.into_rgba32f();
        let (width, height) = rgba.dimensions();
        let pixels = rgba.pixels();
        let mut rgb = Vec::with_capacity(width as usize * height as usize);
        let mut alpha = Vec::with_capacity(if has_alpha { rgb.capacity() } else { 0 });
        for p in pixels {
            rgb.push(
                [p[0], p[1], p[2]].map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }),
            );
            if has_alpha {
                alpha.push(p[3]);
            }
        }
        Ok(Self { width, height, rgb, alpha: has_alpha.then_some(alpha) })
    }

    /// A render seen through [`Tonemap::default`] (clipped, sRGB-encoded), its coverage as
    /// alpha.
    pub fn from_linear(image: &Image) -> Self {
        let tonemap = Tonemap::default();
        let rgb = image.pixels().iter().map(|p| p.map(|v| tonemap.display(v))).collect();
        let alpha = image.coverage().to_vec();
        let opaque = alpha.iter().all(|&a| a >= 1.0);
        Self {
            width: image.width(),
            height: image.height(),
            rgb,
            alpha: (!opaque).then_some(alpha),
        }
    }

    /// An 8-bit sRGB image (no alpha), as [`crate::scene_sampler::camera_png`] makes them.
    pub fn from_srgb8(image: &Srgb8Image) -> Self {
        let rgb = image
            .data
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]].map(|v| f32::from(v) / 255.0))
            .collect();
        Self { width: image.width, height: image.height, rgb, alpha: None }
    }

    /// The photo as 8-bit sRGB (alpha dropped), to look at.
    pub fn to_srgb8(&self) -> Srgb8Image {
        let data =
            self.rgb.iter().flatten().map(|&v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8).collect();
        Srgb8Image { width: self.width, height: self.height, data }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Which pixels show the object: alpha above 1/2 where the photo has alpha, else display
    /// luminance above [`BACKGROUND_LEVEL`].
    fn object_mask(&self) -> Vec<bool> {
        match &self.alpha {
            Some(alpha) => alpha.iter().map(|&a| a > 0.5).collect(),
            None => self
                .rgb
                .iter()
                .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] > BACKGROUND_LEVEL)
                .collect(),
        }
    }

    /// The network's input: a square crop around the object resampled to `side` x `side`,
    /// channel-major `[3, side, side]` display values in [0, 1], the background 0. `what` names
    /// the photo in error messages (its path).
    pub fn network_input(&self, side: u32, what: &str) -> Result<Vec<f32>> {
        let unusable = |why: String| RenderError::Invalid(format!("{what}: {why}"));
        let (w, h) = (self.width as usize, self.height as usize);
        let n = w * h;
        if n == 0 || side == 0 {
            return Err(unusable("empty image".into()));
        }
        let (lo, hi) = self
            .rgb
            .iter()
            .flatten()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let mask = self.object_mask();
        let count = mask.iter().filter(|&&m| m).count();
        if hi - lo < 1.0 / 255.0 && self.alpha.is_none() {
            return Err(unusable(format!(
                "a blank image (every pixel is {:.0}/255): no object to recover from",
                255.0 * lo
            )));
        }
        let least = MIN_OBJECT_PIXELS.max((MIN_OBJECT_FRACTION * n as f64) as usize);
        if count < least {
            return Err(unusable(format!(
                "no object found: {count} pixels stand out from the background ({}), at least \
                 {least} needed; the object must be lit and in front of a plain dark background \
                 or cut out by an alpha channel",
                if self.alpha.is_some() { "alpha > 0.5" } else { "brighter than 15/255" }
            )));
        }
        if self.alpha.is_none() && count as f64 > MAX_OBJECT_FRACTION * n as f64 {
            return Err(unusable(format!(
                "no dark background: {:.1}% of the pixels are brighter than 15/255; give the \
                 object on a plain dark background or with an alpha channel",
                100.0 * count as f64 / n as f64
            )));
        }
        let saturated = self
            .rgb
            .iter()
            .zip(&mask)
            .filter(|(p, &m)| m && p.iter().all(|&v| v >= SATURATED_LEVEL))
            .count();
        if saturated as f64 > MAX_SATURATED_FRACTION * count as f64 {
            return Err(unusable(format!(
                "saturated: {:.0}% of the object's pixels are clipped white; use a shorter \
                 exposure",
                100.0 * saturated as f64 / count as f64
            )));
        }
        // The object's bounding box, and a square around it.
        let (mut x0, mut x1, mut y0, mut y1) = (w, 0, h, 0);
        for (i, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
            let (x, y) = (i % w, i / w);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x + 1), y0.min(y), y1.max(y + 1));
        }
        let box_side = (x1 - x0).max(y1 - y0) as f64;
        let half = 0.5 * box_side * (1.0 + 2.0 * CROP_MARGIN);
        let (cx, cy) = (0.5 * (x0 + x1) as f64, 0.5 * (y0 + y1) as f64);
        let step = 2.0 * half / f64::from(side);
        // Box filter: sub-samples spaced at most one source pixel apart.
        let sub = (step.ceil() as usize).clamp(1, 16);
        let s = side as usize;
        let mut out = vec![0f32; 3 * s * s];
        for oy in 0..s {
            for ox in 0..s {
                let mut sum = [0f64; 3];
                for j in 0..sub {
                    for i in 0..sub {
                        let x = cx - half + (ox as f64 + (i as f64 + 0.5) / sub as f64) * step;
                        let y = cy - half + (oy as f64 + (j as f64 + 0.5) / sub as f64) * step;
                        if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
                            continue;
                        }
                        let p = y as usize * w + x as usize;
                        if mask[p] {
                            for c in 0..3 {
                                sum[c] += f64::from(self.rgb[p][c]);
                            }
                        }
                    }
                }
                let norm = (sub * sub) as f64;
                for c in 0..3 {
                    out[(c * s + oy) * s + ox] = (sum[c] / norm) as f32;
                }
            }
        }
        Ok(out)
    }
}

fn check_size(path: &Path, w: u32, h: u32) -> Result<()> {
    if w == 0 || h == 0 || w > MAX_PHOTO_SIDE || h > MAX_PHOTO_SIDE {
        return Err(RenderError::format(
            path,
            format!("a {w}x{h} image: each side must be 1 to {MAX_PHOTO_SIDE} pixels"),
        ));
    }
    Ok(())
}

/// The network input `[3, side, side]` (display values) as an 8-bit sRGB image, to look at.
pub fn input_preview(values: &[f32], side: u32) -> Srgb8Image {
    let s = side as usize;
    let mut out = Srgb8Image::filled(side, side, [0, 0, 0]);
    for i in 0..s * s {
        for c in 0..3 {
            out.data[3 * i + c] = (values[c * s * s + i].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        }
    }
    out
}

/// Display value of linear `v` under exposure 1 (for tests and previews).
pub fn display(v: f32) -> f32 {
    linear_to_srgb(v.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `size` square image with a lit disk of radius `r` at the centre over black.
    fn disk(size: u32, r: f64, level: u8) -> Srgb8Image {
        let mut img = Srgb8Image::filled(size, size, [0, 0, 0]);
        let c = f64::from(size) / 2.0;
        for y in 0..size {
            for x in 0..size {
                let (dx, dy) = (f64::from(x) + 0.5 - c, f64::from(y) + 0.5 - c);
                if dx * dx + dy * dy < r * r {
                    let i = 3 * (y * size + x) as usize;
                    img.data[i..i + 3].copy_from_slice(&[level, level / 2, level / 4]);
                }
            }
        }
        img
    }

    #[test]
    fn an_object_is_cropped_and_resampled_whatever_the_photo_size() {
        // The same disk at two resolutions and placements gives nearly the same input.
        let small = Photo::from_srgb8(&disk(64, 20.0, 200)).network_input(16, "a").unwrap();
        let big = Photo::from_srgb8(&disk(300, 90.0, 200)).network_input(16, "b").unwrap();
        assert_eq!(small.len(), 3 * 16 * 16);
        let diff: f32 =
            small.iter().zip(&big).map(|(a, b)| (a - b).abs()).sum::<f32>() / small.len() as f32;
        assert!(diff < 0.03, "mean difference {diff}");
        // Centre red ~200/255, corners background.
        let s = 16;
        assert!((small[8 * s + 8] - 200.0 / 255.0).abs() < 1e-3);
        assert_eq!(small[0], 0.0);
        assert!((small[s * s + 8 * s + 8] - 100.0 / 255.0).abs() < 1e-3); // green
    }

    #[test]
    fn unusable_photos_are_refused_with_the_reason() {
        let why = |img: &Srgb8Image| {
            Photo::from_srgb8(img).network_input(16, "p.png").unwrap_err().to_string()
        };
        assert!(why(&Srgb8Image::filled(32, 32, [0, 0, 0])).contains("blank"));
        assert!(why(&Srgb8Image::filled(32, 32, [120, 120, 120])).contains("blank"));
        assert!(why(&disk(64, 1.5, 200)).contains("no object found"));
        let mut bright = disk(64, 60.0, 255);
        bright.data[0] = 3;
        assert!(why(&bright).contains("no dark background"), "{}", why(&bright));
        let mut white = disk(64, 20.0, 255);
        for v in white.data.iter_mut().filter(|v| **v > 0) {
            *v = 255;
        }
        let e = why(&white);
        assert!(e.contains("saturated") && e.starts_with("p.png"), "{e}");
    }

    /// Small files of every format `Photo` reads: PNG (RGB and RGBA), JPEG, EXR.
    fn corpus(dir: &Path) -> Vec<Vec<u8>> {
        use image::ImageFormat;
        let img = disk(40, 14.0, 180);
        let encode = |image: image::DynamicImage, format: ImageFormat| {
            let mut bytes = Vec::new();
            image.write_to(&mut std::io::Cursor::new(&mut bytes), format).unwrap();
            bytes
        };
        let rgb = image::RgbImage::from_raw(40, 40, img.data.clone()).unwrap();
        let rgba = image::RgbaImage::from_fn(40, 40, |x, y| {
            let p = rgb.get_pixel(x, y);
            image::Rgba([p[0], p[1], p[2], if p[0] > 0 { 255 } else { 0 }])
        });
        let linear: Vec<[f32; 3]> =
            (0..40 * 40).map(|i| [0.3, 0.1, (i % 7) as f32 * 0.01]).collect();
        let cov: Vec<f32> = (0..40 * 40).map(|i| if (i / 40) < 20 { 1.0 } else { 0.0 }).collect();
        let exr = dir.join("c.exr");
        Image::from_pixels(40, 40, linear, cov).unwrap().write_exr(&exr).unwrap();
        vec![
            encode(rgb.clone().into(), ImageFormat::Png),
            encode(rgba.into(), ImageFormat::Png),
            encode(rgb.into(), ImageFormat::Jpeg),
            std::fs::read(&exr).unwrap(),
        ]
    }

    #[test]
    fn mutated_photos_are_read_or_refused_never_a_panic() {
        use deepbrdf_data::testing::mutate::{fuzz, inputs, Focus};
        let dir = tempfile::tempdir().unwrap();
        let corpus = corpus(dir.path());
        for bytes in &corpus {
            Photo::from_bytes(bytes, Path::new("seed")).unwrap().network_input(16, "seed").unwrap();
        }
        let n = inputs(2000);
        let origin = Path::new("fuzz.img");
        let report = fuzz(&corpus, 2027, n, Focus { header: 96, header_share: 0.7 }, |b| {
            Photo::from_bytes(b, origin).and_then(|p| p.network_input(16, "fuzz.img"))
        });
        eprintln!("photo reader: {report:?}");
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert!(report.accepted > 0 && report.rejected > 0, "{report:?}");
    }

    #[test]
    fn an_exr_larger_than_the_limit_is_refused_before_its_pixels_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let wide = crate::image::MAX_SIZE + 1;
        let n = wide as usize;
        let path = dir.path().join("wide.exr");
        Image::from_pixels(wide, 1, vec![[0.5; 3]; n], vec![1.0; n])
            .unwrap()
            .write_exr(&path)
            .unwrap();
        let e = Photo::read(&path).unwrap_err().to_string();
        assert!(e.contains("wide.exr") && e.contains("at most 8192"), "{e}");
    }

    #[test]
    fn files_of_every_format_read_alike() {
        let dir = tempfile::tempdir().unwrap();
        let img = disk(48, 16.0, 180);
        let png = dir.path().join("a.png");
        img.write_png(&png).unwrap();
        let (read, direct) = (Photo::read(&png).unwrap(), Photo::from_srgb8(&img));
        assert_eq!((read.width(), read.height(), read.alpha.is_none()), (48, 48, true));
        for (a, b) in read.rgb.iter().flatten().zip(direct.rgb.iter().flatten()) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        // EXR: linear values with coverage as alpha.
        let linear: Vec<[f32; 3]> = (0..48 * 48).map(|_| [0.3, 0.1, 0.05]).collect();
        let cov: Vec<f32> = (0..48 * 48).map(|i| if (i / 48) < 24 { 1.0 } else { 0.0 }).collect();
        let exr = dir.path().join("a.exr");
        Image::from_pixels(48, 48, linear, cov).unwrap().write_exr(&exr).unwrap();
        let input = Photo::read(&exr).unwrap().network_input(8, "a.exr").unwrap();
        let centre = 4 * 8 + 4;
        assert!((input[centre] - display(0.3)).abs() < 1e-4, "{}", input[centre]);
        assert!((input[128 + centre] - display(0.05)).abs() < 1e-4);
        // A file that is not an image.
        let bad = dir.path().join("b.png");
        std::fs::write(&bad, b"not a png at all").unwrap();
        let e = Photo::read(&bad).unwrap_err().to_string();
        assert!(e.contains("b.png") && e.contains("not a readable"), "{e}");
    }
}

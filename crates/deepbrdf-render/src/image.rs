//! Images: linear HDR radiance with a coverage channel, written as OpenEXR (the `exr` crate,
//! coverage as alpha) or tonemapped to 8-bit sRGB PNG (the `image` crate). Every file is written
//! to a temporary file beside its target and renamed into place.

use crate::error::{RenderError, Result};
use std::path::Path;

/// Largest image side accepted, rendered or read (memory stays under a few hundred MB).
pub const MAX_SIZE: u32 = 8192;

/// A linear-radiance RGB image (f32) with per-pixel coverage in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    rgb: Vec<[f32; 3]>,
    coverage: Vec<f32>,
}

impl Image {
    /// A black image with no coverage.
    pub fn black(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, rgb: vec![[0.0; 3]; n], coverage: vec![0.0; n] }
    }

    /// An image from pixel values (row-major from the top-left) and coverage.
    pub fn from_pixels(
        width: u32,
        height: u32,
        rgb: Vec<[f32; 3]>,
        coverage: Vec<f32>,
    ) -> Result<Self> {
        let n = width as usize * height as usize;
        if rgb.len() != n || coverage.len() != n {
            return Err(RenderError::Invalid(format!(
                "a {width}x{height} image needs {n} pixels, got {} and {} coverage values",
                rgb.len(),
                coverage.len()
            )));
        }
        Ok(Self { width, height, rgb, coverage })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Linear radiance per pixel, row-major from the top-left.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// Fraction of each pixel's samples that hit the shape.
    pub fn coverage(&self) -> &[f32] {
        &self.coverage
    }

    /// Radiance of pixel (x, y).
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.rgb[y as usize * self.width as usize + x as usize]
    }

    /// The pixel-wise mean of images of one size (renders of one scene with different seeds
    /// average to a render with their samples pooled).
    pub fn mean(images: &[Image]) -> Result<Image> {
        let first =
            images.first().ok_or_else(|| RenderError::Invalid("no images to average".into()))?;
        let (w, h) = (first.width, first.height);
        if images.iter().any(|i| i.width != w || i.height != h) {
            return Err(RenderError::Invalid("images to average differ in size".into()));
        }
        let scale = 1.0 / images.len() as f32;
        let mut mean = Image::black(w, h);
        for image in images {
            for (m, p) in mean.rgb.iter_mut().zip(&image.rgb) {
                (0..3).for_each(|c| m[c] += p[c] * scale);
            }
            for (m, c) in mean.coverage.iter_mut().zip(&image.coverage) {
                *m += c * scale;
            }
        }
        Ok(mean)
    }

    /// The coverage-weighted mean radiance of the pixels the object covers (a material's colour
    /// as a swatch; the sum of `coverage * radiance` over the sum of coverage), `None` where no
    /// pixel shows the object.
    pub fn object_mean(&self) -> Option<[f32; 3]> {
        let (mut sum, mut weight) = ([0f64; 3], 0f64);
        for (p, &c) in self.rgb.iter().zip(&self.coverage) {
            if c > 0.0 {
                (0..3).for_each(|k| sum[k] += f64::from(c) * f64::from(p[k]));
                weight += f64::from(c);
            }
        }
        (weight > 0.0).then(|| sum.map(|s| (s / weight) as f32))
    }

    pub(crate) fn buffers_mut(&mut self) -> (&mut [[f32; 3]], &mut [f32]) {
        (&mut self.rgb, &mut self.coverage)
    }

    /// Tonemapped 8-bit sRGB, composited over `background` (an 8-bit sRGB colour) where coverage
    /// is partial or zero.
    pub fn to_srgb8(&self, tonemap: &Tonemap, background: [u8; 3]) -> Srgb8Image {
        let bg = background.map(|b| srgb_to_linear(f32::from(b) / 255.0));
        let mut data = Vec::with_capacity(self.rgb.len() * 3);
        for (p, &c) in self.rgb.iter().zip(&self.coverage) {
            for k in 0..3 {
                let v = tonemap.apply(p[k]) + (1.0 - c.clamp(0.0, 1.0)) * bg[k];
                data.push(encode_srgb8(v));
            }
        }
        Srgb8Image { width: self.width, height: self.height, data }
    }

    /// Writes a tonemapped PNG over a black background.
    pub fn write_png(&self, path: &Path, tonemap: &Tonemap) -> Result<()> {
        self.to_srgb8(tonemap, [0, 0, 0]).write_png(path)
    }

    /// Writes an OpenEXR file: linear R, G, B (f32) and coverage as A.
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        use exr::prelude::{Image as ExrImage, SpecificChannels, Vec2, WritableImage};
        let w = self.width as usize;
        let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let p = self.rgb[y * w + x];
            (p[0], p[1], p[2], self.coverage[y * w + x])
        });
        let image = ExrImage::from_channels((w, self.height as usize), channels);
        let mut bytes = std::io::Cursor::new(Vec::new());
        image
            .write()
            .to_buffered(&mut bytes)
            .map_err(|e| RenderError::format(path, format!("cannot encode EXR: {e}")))?;
        Ok(deepbrdf_data::files::write_atomic(path, bytes.get_ref())?)
    }

    /// Reads an OpenEXR file written by [`Image::write_exr`] (or any RGB(A) EXR; missing alpha
    /// reads as full coverage).
    pub fn read_exr(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path)
            .map_err(|e| RenderError::format(path, format!("cannot read: {e}")))?;
        Self::exr_from_bytes(&bytes, path)
    }

    /// [`Image::read_exr`] of a file's bytes (`origin` names it in errors). The header is read
    /// first and a layer larger than [`MAX_SIZE`] on a side is refused
    /// before any pixel memory is allocated.
    pub fn exr_from_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        use exr::prelude::*;
        let bad = |e: exr::error::Error| {
            RenderError::format(origin, format!("not a readable RGB EXR image: {e}"))
        };
        let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
            .map_err(bad)?;
        let max = MAX_SIZE as usize;
        for header in &meta.headers {
            let size = header.layer_size;
            if size.width() > max || size.height() > max {
                return Err(RenderError::format(
                    origin,
                    format!(
                        "a {}x{} EXR layer: each side must be at most {max} pixels",
                        size.width(),
                        size.height()
                    ),
                ));
            }
        }
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |resolution, _| {
                    let (w, h) = (resolution.width(), resolution.height());
                    (w, vec![[0.0f32; 4]; w * h])
                },
                |(w, pixels): &mut (usize, Vec<[f32; 4]>),
                 pos,
                 (r, g, b, a): (f32, f32, f32, f32)| {
                    pixels[pos.y() * *w + pos.x()] = [r, g, b, a];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(bad)?;
        let size = image.layer_data.size;
        let (_, pixels) = image.layer_data.channel_data.pixels;
        let (w, h) = (u32::try_from(size.width()), u32::try_from(size.height()));
        let (Ok(w), Ok(h)) = (w, h) else {
            return Err(RenderError::format(origin, "image too large"));
        };
        let rgb = pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let coverage = pixels.iter().map(|p| p[3]).collect();
        Self::from_pixels(w, h, rgb, coverage)
    }
}

/// Display mapping of linear radiance: scale by `exposure`, clip to [0, 1] (then sRGB encode).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tonemap {
    pub exposure: f32,
}

impl Default for Tonemap {
    fn default() -> Self {
        Self { exposure: 1.0 }
    }
}

impl Tonemap {
    /// Tonemapped linear value in [0, 1] (NaN maps to 0).
    #[inline]
    pub fn apply(&self, v: f32) -> f32 {
        let v = v * self.exposure;
        if v.is_nan() {
            0.0
        } else {
            v.clamp(0.0, 1.0)
        }
    }

    /// Tonemapped and sRGB-encoded value in [0, 1].
    #[inline]
    pub fn display(&self, v: f32) -> f32 {
        linear_to_srgb(self.apply(v))
    }

    /// A linear RGB radiance as an 8-bit sRGB colour (as [`Image::to_srgb8`] encodes a pixel).
    pub fn srgb8(&self, rgb: [f32; 3]) -> [u8; 3] {
        rgb.map(|v| encode_srgb8(self.apply(v)))
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`linear_to_srgb`].
#[inline]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[inline]
fn encode_srgb8(linear: f32) -> u8 {
    (linear_to_srgb(linear.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
}

/// JPEG quality of the figures written by [`Srgb8Image::write_figure`].
pub const FIGURE_JPEG_QUALITY: u8 = 95;

/// An 8-bit sRGB image, row-major RGB bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Srgb8Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

impl Srgb8Image {
    /// A `width x height` image filled with `colour`.
    pub fn filled(width: u32, height: u32, colour: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, data: colour.iter().copied().cycle().take(3 * n).collect() }
    }

    /// Copies `src` with its top-left corner at (`x`, `y`), clipped to this image.
    pub fn blit(&mut self, src: &Srgb8Image, x: u32, y: u32) {
        for sy in 0..src.height {
            let ty = y + sy;
            if ty >= self.height {
                break;
            }
            let w = src.width.min(self.width.saturating_sub(x)) as usize;
            let s = (sy * src.width) as usize * 3;
            let t = (ty as usize * self.width as usize + x as usize) * 3;
            self.data[t..t + 3 * w].copy_from_slice(&src.data[s..s + 3 * w]);
        }
    }

    /// The image enlarged by the integer factor `f`, each pixel repeated `f x f` times
    /// (nearest neighbour: a small render shown large stays sharp).
    pub fn upscaled(&self, f: u32) -> Srgb8Image {
        let (w, h) = (self.width * f, self.height * f);
        let mut out = Srgb8Image::filled(w, h, [0, 0, 0]);
        for y in 0..h {
            for x in 0..w {
                let s = 3 * ((y / f) * self.width + x / f) as usize;
                let t = 3 * (y * w + x) as usize;
                out.data[t..t + 3].copy_from_slice(&self.data[s..s + 3]);
            }
        }
        out
    }

    /// Encodes as PNG and writes it atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        let png = self.png_bytes().map_err(|e| RenderError::format(path, e.to_string()))?;
        Ok(deepbrdf_data::files::write_atomic(path, &png)?)
    }

    /// Writes a figure atomically: JPEG at quality [`FIGURE_JPEG_QUALITY`] for a `.jpg` or
    /// `.jpeg` path (a committed figure of renders: a quarter of the PNG's size with no change a
    /// reader sees), PNG otherwise.
    pub fn write_figure(&self, path: &Path) -> Result<()> {
        let jpeg = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("jpg") || e.eq_ignore_ascii_case("jpeg"));
        if !jpeg {
            return self.write_png(path);
        }
        use image::codecs::jpeg::JpegEncoder;
        use image::ImageEncoder;
        if self.data.len() != 3 * self.width as usize * self.height as usize {
            return Err(RenderError::Invalid("image buffer has the wrong size".into()));
        }
        let mut bytes = Vec::new();
        JpegEncoder::new_with_quality(&mut bytes, FIGURE_JPEG_QUALITY)
            .write_image(&self.data, self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| RenderError::format(path, format!("cannot encode JPEG: {e}")))?;
        Ok(deepbrdf_data::files::write_atomic(path, &bytes)?)
    }

    /// The PNG encoding of the image, at the encoder's best compression with adaptive filters
    /// (lossless either way; figures are committed, and the smaller file is worth the time).
    pub fn png_bytes(&self) -> Result<Vec<u8>> {
        use image::codecs::png::{CompressionType, FilterType, PngEncoder};
        use image::ImageEncoder;
        if self.data.len() != 3 * self.width as usize * self.height as usize {
            return Err(RenderError::Invalid("image buffer has the wrong size".into()));
        }
        let mut png = Vec::new();
        PngEncoder::new_with_quality(&mut png, CompressionType::Best, FilterType::Adaptive)
            .write_image(&self.data, self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| RenderError::Invalid(format!("cannot encode PNG: {e}")))?;
        Ok(png)
    }

    /// The RGB image of a PNG file's bytes `png` (read from `path`, which errors name); `None`
    /// for a PNG of another colour type (grey, alpha, 16 bits), which this type cannot hold.
    pub fn from_png(path: &Path, png: &[u8]) -> Result<Option<Srgb8Image>> {
        let bad = |e: image::ImageError| RenderError::format(path, format!("not a PNG image: {e}"));
        let decoded =
            image::load_from_memory_with_format(png, image::ImageFormat::Png).map_err(bad)?;
        Ok(match decoded {
            image::DynamicImage::ImageRgb8(rgb) => {
                let (width, height) = rgb.dimensions();
                Some(Srgb8Image { width, height, data: rgb.into_raw() })
            }
            _ => None,
        })
    }
}

/// Control points of matplotlib's "inferno" colour map (sRGB, at 0, 1/8, ..., 1).
const INFERNO: [[f32; 3]; 9] = [
    [0.001, 0.000, 0.014],
    [0.122, 0.047, 0.282],
    [0.333, 0.060, 0.430],
    [0.533, 0.133, 0.416],
    [0.729, 0.212, 0.333],
    [0.891, 0.349, 0.200],
    [0.976, 0.554, 0.039],
    [0.976, 0.789, 0.197],
    [0.988, 0.998, 0.645],
];

/// False colour of `t` in [0, 1] (clamped): the inferno map, dark (0) to bright yellow (1).
pub fn false_colour(t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * (INFERNO.len() - 1) as f32;
    let i = (t.floor() as usize).min(INFERNO.len() - 2);
    let f = t - i as f32;
    std::array::from_fn(|c| {
        let v = INFERNO[i][c] * (1.0 - f) + INFERNO[i + 1][c] * f;
        (v * 255.0 + 0.5) as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn object_mean_weights_by_coverage_and_srgb8_encodes_like_a_pixel() {
        // Pixels 0 (coverage 1) and 1 (0.5) are on the object, pixel 2 is not:
        // (1 * 0.2 + 0.5 * 0.8) / 1.5 = 0.4 in every channel.
        let image =
            Image::from_pixels(3, 1, vec![[0.2; 3], [0.8; 3], [9.0; 3]], vec![1.0, 0.5, 0.0])
                .unwrap();
        let mean = image.object_mean().unwrap();
        assert!(mean.iter().all(|v| (v - 0.4).abs() < 1e-6), "{mean:?}");
        assert_eq!(Image::black(2, 2).object_mean(), None);
        let t = Tonemap::default();
        let one = Image::from_pixels(1, 1, vec![[0.4, 0.0, 2.0]], vec![1.0]).unwrap();
        assert_eq!(t.srgb8([0.4, 0.0, 2.0]).to_vec(), one.to_srgb8(&t, [0; 3]).data);
    }

    #[test]
    fn upscaling_repeats_each_pixel_in_a_block() {
        let img = Srgb8Image { width: 2, height: 1, data: vec![1, 2, 3, 4, 5, 6] };
        let up = img.upscaled(2);
        assert_eq!((up.width, up.height), (4, 2));
        let row = [1, 2, 3, 1, 2, 3, 4, 5, 6, 4, 5, 6];
        assert_eq!(up.data, [row, row].concat());
        assert_eq!(img.upscaled(1), img);
    }

    #[test]
    fn srgb_round_trip_and_known_values() {
        assert_eq!(encode_srgb8(0.0), 0);
        assert_eq!(encode_srgb8(1.0), 255);
        // 18% grey encodes to about 118 (0.4614 * 255).
        assert_eq!(encode_srgb8(0.18), 118);
        for v in [0.001f32, 0.02, 0.3, 0.9] {
            assert!((srgb_to_linear(linear_to_srgb(v)) - v).abs() < 1e-6);
        }
    }

    #[test]
    fn exr_and_png_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let rgb = (0..12).map(|i| [i as f32 * 0.5, 2.0, -0.0]).collect();
        let cov = (0..12).map(|i| (i % 2) as f32).collect();
        let img = Image::from_pixels(4, 3, rgb, cov).unwrap();
        let exr_path = dir.path().join("a.exr");
        img.write_exr(&exr_path).unwrap();
        assert_eq!(Image::read_exr(&exr_path).unwrap(), img);
        let png_path = dir.path().join("a.png");
        img.write_png(&png_path, &Tonemap::default()).unwrap();
        let back = image::open(&png_path).unwrap().to_rgb8();
        assert_eq!((back.width(), back.height()), (4, 3));
        // Pixel 1: radiance (0.5, 2, 0), coverage 1 -> (188, 255, 0).
        assert_eq!(back.get_pixel(1, 0).0, [188, 255, 0]);
        // No temp files left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn a_figure_is_written_as_its_extension_says() {
        let dir = tempfile::tempdir().unwrap();
        let mut img = Srgb8Image::filled(16, 8, [200, 120, 40]);
        img.data[0..3].copy_from_slice(&[0, 0, 0]);
        for (name, format) in
            [("f.jpg", image::ImageFormat::Jpeg), ("f.png", image::ImageFormat::Png)]
        {
            let path = dir.path().join(name);
            img.write_figure(&path).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(image::guess_format(&bytes).unwrap(), format, "{name}");
            let back = image::load_from_memory(&bytes).unwrap().to_rgb8();
            assert_eq!((back.width(), back.height()), (16, 8));
            // Quality 95: a flat colour comes back within a few levels.
            let p = back.get_pixel(8, 4).0;
            assert!(p.iter().zip([200u8, 120, 40]).all(|(a, b)| a.abs_diff(b) <= 3), "{p:?}");
        }
    }

    #[test]
    fn reading_a_foreign_file_names_it() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.exr");
        std::fs::write(&p, b"not an exr").unwrap();
        let err = Image::read_exr(&p).unwrap_err().to_string();
        assert!(err.contains("bad.exr"), "{err}");
    }

    #[test]
    fn false_colour_ends() {
        assert_eq!(false_colour(0.0), [0, 0, 4]);
        assert_eq!(false_colour(1.0), [252, 254, 164]);
        assert_eq!(false_colour(f32::NAN), false_colour(0.0));
    }
}

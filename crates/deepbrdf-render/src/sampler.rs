//! The sample points of one pixel: where each of its samples falls in the pixel and which random
//! numbers its light and BRDF strategies draw from.
//!
//! [`Sampler::Sobol`] (the default) gives every pixel its own Owen-scrambled Sobol sequence
//! (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020, through the `sobol_burley` crate):
//! each 4-D set of dimensions is a scrambled Sobol point set with its own seed ("padding", §4 of
//! the paper), so the pixel positions, the light samples and the BRDF samples are each stratified
//! over the pixel's samples, the pixel position jointly with the strongest strategy's pair
//! ([`PixelSampler::shade_point`]), the sets independent of one another. Randomised quasi-Monte
//! Carlo: unbiased for every seed, two seeds are independent estimates, and the error falls
//! faster than `1 / sqrt(spp)` wherever the integrand is smooth (best at powers of two).
//! [`Sampler::Independent`] draws every number from the pixel's own ChaCha8 stream, as the
//! renderer did before (render sets made then record it and render the same bytes).

use crate::error::{RenderError, Result};
use crate::light::MAX_STRATEGIES;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How a pixel's samples draw their random numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Sampler {
    /// Independent uniform numbers from a ChaCha8 stream per pixel.
    Independent,
    /// Owen-scrambled Sobol points, a scramble per pixel and per 4-D set of dimensions.
    #[default]
    Sobol,
}

impl FromStr for Sampler {
    type Err = RenderError;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "independent" => Ok(Self::Independent),
            "sobol" => Ok(Self::Sobol),
            _ => Err(RenderError::Invalid(format!(
                "sampler '{s}': expected 'sobol' or 'independent'"
            ))),
        }
    }
}

impl fmt::Display for Sampler {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Independent => "independent",
            Self::Sobol => "sobol",
        })
    }
}

impl Sampler {
    /// The sampler of settings stored before there was a choice (render-set manifests written
    /// with the independent sampler, which did not record it).
    pub fn stored_default() -> Self {
        Self::Independent
    }
}

/// Largest sample count per pixel a [`Sampler::Sobol`] sequence holds (`sobol_burley`'s limit).
pub const MAX_SOBOL_SAMPLES: u32 = 1 << 16;

/// The random numbers of one shading point: a pair per light strategy and a pair for the BRDF's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadePoint {
    /// One pair per light strategy of the environment (sun, sky).
    pub light: [[f64; 2]; MAX_STRATEGIES],
    /// The BRDF strategy's pair.
    pub brdf: [f64; 2],
}

/// The random numbers of one pixel's samples, for one seed.
pub enum PixelSampler {
    /// A ChaCha8 stream (the pixel's own).
    Independent(Box<ChaCha8Rng>),
    /// Per-set scramble seeds of the pixel, and the first set of the latest sample it was
    /// computed for (the pixel position and the BRDF pair share it: computed once per sample).
    Sobol { seeds: [u32; 2], first: (u32, [f64; 4]) },
}

impl PixelSampler {
    /// The sampler of pixel `pixel` (row-major index) of a render with seed `seed`.
    pub fn new(kind: Sampler, seed: u64, pixel: u64) -> Self {
        match kind {
            Sampler::Independent => {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(pixel);
                Self::Independent(Box::new(rng))
            }
            Sampler::Sobol => {
                let base = splitmix64(seed ^ splitmix64(pixel.wrapping_add(0x51_7cc1_b727_220a)));
                let fold = |x: u64| (x ^ (x >> 32)) as u32;
                let seeds =
                    [fold(splitmix64(base)), fold(splitmix64(base ^ 0x2545_f491_4f6c_dd1d))];
                // No sample has index u32::MAX (at most MAX_SOBOL_SAMPLES): nothing cached yet.
                Self::Sobol { seeds, first: (u32::MAX, [0.0; 4]) }
            }
        }
    }

    /// Dimension set `set` of sample `index` (Sobol only).
    #[inline]
    fn set(seeds: &[u32; 2], index: u32, set: usize) -> [f64; 4] {
        sobol_burley::sample_4d(index, 0, seeds[set]).map(f64::from)
    }

    /// The first dimension set of sample `index`, computed once per sample (Sobol only).
    #[inline]
    fn first_set(seeds: &[u32; 2], first: &mut (u32, [f64; 4]), index: u32) -> [f64; 4] {
        if first.0 != index {
            *first = (index, Self::set(seeds, index, 0));
        }
        first.1
    }

    /// Position of sample `index` (< [`MAX_SOBOL_SAMPLES`]) in its pixel, in [0, 1)^2.
    #[inline]
    pub fn pixel_offset(&mut self, index: u32) -> [f64; 2] {
        match self {
            Self::Independent(rng) => [rng.random(), rng.random()],
            Self::Sobol { seeds, first } => {
                let s = Self::first_set(seeds, first, index);
                [s[0], s[1]]
            }
        }
    }

    /// The numbers of sample `index`'s shading point with `lights` light strategies: the
    /// independent sampler draws them as the renderer always has, the light strategies' pairs
    /// first, only when the sample hits the shape.
    ///
    /// The Sobol sampler puts the pair of the strategy that carries the most light in the pixel
    /// position's 4-D set, so that position and that pair are stratified jointly, not only each
    /// on its own: the first light strategy (the sun) when there is one, else the BRDF's. A
    /// sharp lobe's image of the sun is about a pixel wide and its value depends on where in
    /// the pixel the sample falls *and* where in the sun's disk its light sample falls; with the
    /// two in separate sets their interaction would be sampled as by independent numbers
    /// (the noise this halves on sharp lobes: docs/performance.md).
    #[inline]
    pub fn shade_point(&mut self, index: u32, lights: usize) -> ShadePoint {
        match self {
            Self::Independent(rng) => {
                let mut light = [[0.0; 2]; MAX_STRATEGIES];
                for pair in &mut light[..lights] {
                    *pair = [rng.random(), rng.random()];
                }
                ShadePoint { light, brdf: [rng.random(), rng.random()] }
            }
            Self::Sobol { seeds, first } => {
                let (a, b) = (Self::first_set(seeds, first, index), Self::set(seeds, index, 1));
                match lights {
                    0 => ShadePoint { light: [[b[0], b[1]], [b[2], b[3]]], brdf: [a[2], a[3]] },
                    _ => ShadePoint { light: [[a[2], a[3]], [b[2], b[3]]], brdf: [b[0], b[1]] },
                }
            }
        }
    }
}

/// SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix.
#[inline]
fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_points_are_stratified_per_pair_and_differ_between_pixels() {
        // 64 samples of one pixel: every 8x8 cell of each 2-D pair (pixel position, sun, sky,
        // BRDF) holds exactly one point (a scrambled (0, 2)-sequence prefix of 2^6 points), and
        // another pixel's points differ.
        let points = |pixel| {
            let mut s = PixelSampler::new(Sampler::Sobol, 7, pixel);
            (0..64)
                .map(|i| {
                    let p = s.shade_point(i, 2);
                    [s.pixel_offset(i), p.light[0], p.light[1], p.brdf]
                })
                .collect::<Vec<_>>()
        };
        let a = points(3);
        for pair in 0..4 {
            let mut seen = [false; 64];
            for p in &a {
                let [x, y] = p[pair];
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                let cell = (x * 8.0) as usize * 8 + (y * 8.0) as usize;
                assert!(!seen[cell], "pair {pair}: cell {cell} twice");
                seen[cell] = true;
            }
        }
        assert_ne!(a, points(4));
        assert_eq!(a, points(3));
        // The pairs are scrambled independently: not the same numbers.
        assert!(a.iter().all(|p| p[0] != p[3] && p[1] != p[2]));
    }

    #[test]
    fn sobol_position_and_sun_pair_are_stratified_jointly() {
        // Under sun and sky the sun pair comes from the position's set, where the BRDF pair is
        // without light strategies: the projections of (position, sun) onto every two of their
        // four dimensions are stratified over 64 samples (8x8 cells, one point each), which two
        // independently scrambled sets would not be.
        let mut s = PixelSampler::new(Sampler::Sobol, 11, 5);
        let points: Vec<[f64; 4]> = (0..64)
            .map(|i| {
                let sun = s.shade_point(i, 2).light[0];
                assert_eq!(sun, s.shade_point(i, 0).brdf);
                let [x, y] = s.pixel_offset(i);
                [x, y, sun[0], sun[1]]
            })
            .collect();
        for (d, e) in [(0, 2), (0, 3), (1, 2), (1, 3)] {
            let mut seen = [false; 64];
            for p in &points {
                let cell = (p[d] * 8.0) as usize * 8 + (p[e] * 8.0) as usize;
                assert!(!seen[cell], "dimensions {d}, {e}: cell {cell} twice");
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn independent_numbers_follow_the_pixel_stream_in_the_old_order() {
        let mut s = PixelSampler::new(Sampler::Independent, 5, 9);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        rng.set_stream(9);
        let want: Vec<f64> = (0..8).map(|_| rng.random()).collect();
        let o = s.pixel_offset(0);
        let p = s.shade_point(0, 1);
        assert_eq!([o[0], o[1], p.light[0][0], p.light[0][1], p.brdf[0], p.brdf[1]], want[..6]);
        let o = s.pixel_offset(1);
        assert_eq!(o, [want[6], want[7]]);
    }
}

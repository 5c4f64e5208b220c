//! The sampler that covers the space of materials: each family of [`Family::ALL`] with its
//! colours drawn in hue, saturation and value, roughness log-uniform over [`ROUGHNESS_RANGE`],
//! dielectric indices over [`DIELECTRIC_ETA`], metals from the measured IOR table
//! ([`super::conductors`]). Material `index` of `seed` depends only on (seed, index): its
//! generator is ChaCha8 seeded with `seed` on stream `index`, so a corpus is generated in any
//! order, in parallel, and resumed by index range. A material whose parts together would reflect
//! more light than arrives is scaled down ([`super::energy`]).

use super::coat::Coat;
use super::conductors::conductors;
use super::diffuse::Diffuse;
use super::energy;
use super::fresnel::Fresnel;
use super::material::{Family, Material};
use super::microfacet::{Distribution, Lobe};
use super::retro::Retro;
use super::sheen::Sheen;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Roughness (alpha) range of the main lobes, sampled log-uniformly.
pub const ROUGHNESS_RANGE: (f64, f64) = (0.005, 1.0);
/// Index range of the dielectric lobes.
pub const DIELECTRIC_ETA: (f64, f64) = (1.3, 2.0);
/// Index range of clear coats (lacquers, varnishes).
pub const COAT_ETA: (f64, f64) = (1.4, 1.6);
/// Fraction of lobes with Beckmann's distribution (the rest GGX).
const BECKMANN_SHARE: f64 = 0.3;

/// Material `index` of the corpus of `seed`, its family drawn uniformly from [`Family::ALL`].
pub fn sample(seed: u64, index: u64) -> Material {
    let mut rng = generator(seed, index);
    let family = Family::ALL[rng.random_range(0..Family::ALL.len())];
    draw(family, &mut rng)
}

/// Material `index` of `seed` drawn from `family` (for figures and tests of one family): the
/// generator of [`sample`], with the number `sample` spends on the family skipped.
pub fn sample_family(family: Family, seed: u64, index: u64) -> Material {
    let mut rng = generator(seed, index);
    let _: u32 = rng.random();
    draw(family, &mut rng)
}

/// The generator of material `index` of `seed`.
fn generator(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

fn draw(family: Family, rng: &mut ChaCha8Rng) -> Material {
    let mut m =
        Material { family, diffuse: None, lobes: vec![], sheen: None, retro: None, coat: None };
    match family {
        Family::Plastic => {
            m.diffuse = Some(diffuse_base(rng, (0.0, 0.9), (0.02, 0.9)));
            let alpha = roughness(rng);
            m.lobes.push(dielectric_lobe(rng, alpha, 1.0));
        }
        Family::Metal => {
            let alpha = roughness(rng);
            m.lobes.push(metal_lobe(rng, alpha));
        }
        Family::RoughDiffuse => {
            let albedo = colour(rng, (0.0, 1.0), (0.03, 0.95));
            m.diffuse = Some(Diffuse::OrenNayar { albedo, sigma: uniform(rng, (0.1, 1.0)) });
        }
        Family::Fabric => {
            let albedo = colour(rng, (0.0, 1.0), (0.03, 0.8));
            m.diffuse = Some(Diffuse::OrenNayar { albedo, sigma: uniform(rng, (0.3, 1.0)) });
            let colour = match rng.random_bool(0.5) {
                true => albedo.map(|a| (a * uniform(rng, (1.0, 1.5))).min(1.0)),
                false => [uniform(rng, (0.2, 1.0)); 3],
            };
            m.sheen = Some(Sheen { colour, roughness: uniform(rng, (0.1, 1.0)) });
        }
        Family::CoatedPaint => {
            m.diffuse = Some(Diffuse::Lambertian { albedo: colour(rng, (0.2, 1.0), (0.02, 0.7)) });
            if rng.random_bool(0.6) {
                // Metallic flakes: a rough, dimmed metal lobe under the coat.
                let alpha = log_uniform(rng, (0.1, 0.6));
                let mut flakes = metal_lobe(rng, alpha);
                let dim = uniform(rng, (0.2, 0.7));
                flakes.tint = flakes.tint.map(|t| t * dim);
                m.lobes.push(flakes);
            }
            m.coat =
                Some(Coat { eta: uniform(rng, COAT_ETA), alpha: log_uniform(rng, (0.005, 0.1)) });
        }
        Family::TwoLobe => {
            m.diffuse = Some(diffuse_base(rng, (0.0, 0.7), (0.02, 0.8)));
            let sharp = log_uniform(rng, (ROUGHNESS_RANGE.0, 0.3));
            let wide = (sharp * uniform(rng, (3.0, 15.0))).min(ROUGHNESS_RANGE.1);
            let first = uniform(rng, (0.5, 0.85));
            let lobe = dielectric_lobe(rng, sharp, first);
            let eta = lobe.fresnel;
            m.lobes.push(lobe);
            m.lobes.push(Lobe { alpha: wide, tint: [1.0 - first; 3], fresnel: eta, ..lobe });
        }
        Family::RetroReflective => {
            m.diffuse = Some(diffuse_base(rng, (0.0, 1.0), (0.02, 0.6)));
            let colour = colour(rng, (0.0, 0.6), (0.1, 0.8));
            m.retro = Some(Retro { colour, exponent: log_uniform(rng, (2.0, 200.0)) });
            if rng.random_bool(0.5) {
                let alpha = roughness(rng);
                m.lobes.push(dielectric_lobe(rng, alpha, 1.0));
            }
        }
    }
    energy::conserve(m)
}

/// A Lambertian or (half of the time) Oren-Nayar base.
fn diffuse_base(rng: &mut ChaCha8Rng, saturation: (f64, f64), value: (f64, f64)) -> Diffuse {
    let albedo = colour(rng, saturation, value);
    match rng.random_bool(0.5) {
        true => Diffuse::Lambertian { albedo },
        false => Diffuse::OrenNayar { albedo, sigma: uniform(rng, (0.05, 0.6)) },
    }
}

/// A dielectric lobe of roughness `alpha` and weight `tint`.
fn dielectric_lobe(rng: &mut ChaCha8Rng, alpha: f64, tint: f64) -> Lobe {
    Lobe {
        distribution: distribution(rng),
        alpha,
        fresnel: Fresnel::Dielectric { eta: uniform(rng, DIELECTRIC_ETA) },
        tint: [tint; 3],
    }
}

/// A metal of the IOR table, half of the time tinted by a light colour.
fn metal_lobe(rng: &mut ChaCha8Rng, alpha: f64) -> Lobe {
    let fresnel = match conductors() {
        Ok(all) => all[rng.random_range(0..all.len())].fresnel(),
        // The compiled-in table is checked by the tests; a Schlick grey stands in otherwise.
        Err(_) => Fresnel::Schlick { f0: [0.9; 3] },
    };
    let tint = match rng.random_bool(0.5) {
        true => colour(rng, (0.0, 0.5), (0.6, 1.0)),
        false => [1.0; 3],
    };
    Lobe { distribution: distribution(rng), alpha, fresnel, tint }
}

fn distribution(rng: &mut ChaCha8Rng) -> Distribution {
    match rng.random_bool(BECKMANN_SHARE) {
        true => Distribution::Beckmann,
        false => Distribution::Ggx,
    }
}

/// A main lobe's roughness, log-uniform over [`ROUGHNESS_RANGE`].
fn roughness(rng: &mut ChaCha8Rng) -> f64 {
    log_uniform(rng, ROUGHNESS_RANGE)
}

fn uniform(rng: &mut ChaCha8Rng, (lo, hi): (f64, f64)) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

fn log_uniform(rng: &mut ChaCha8Rng, (lo, hi): (f64, f64)) -> f64 {
    uniform(rng, (lo.ln(), hi.ln())).exp().clamp(lo, hi)
}

/// A colour with uniform hue and saturation and value in the given ranges.
fn colour(rng: &mut ChaCha8Rng, saturation: (f64, f64), value: (f64, f64)) -> [f64; 3] {
    let h = uniform(rng, (0.0, 1.0));
    hsv_to_rgb(h, uniform(rng, saturation), uniform(rng, value))
}

/// HSV (hue in [0, 1), saturation and value in [0, 1]) to RGB in [0, 1] (Smith 1978, "Color
/// Gamut Transform Pairs", the hexcone model).
pub fn hsv_to_rgb(h: f64, s: f64, v: f64) -> [f64; 3] {
    let h6 = (h.rem_euclid(1.0)) * 6.0;
    let sector = h6.floor();
    let f = h6 - sector;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match sector as u32 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn materials_depend_only_on_seed_and_index() {
        let a: Vec<Material> = (0..50).map(|i| sample(11, i)).collect();
        let b: Vec<Material> = (0..50).rev().map(|i| sample(11, i)).rev().collect();
        assert_eq!(a, b);
        assert_ne!(sample(11, 0), sample(12, 0));
        assert_ne!(sample(11, 0), sample(11, 1));
    }

    #[test]
    fn the_sampler_covers_the_families_and_the_roughness_range() {
        let n = 3000;
        let mut families = HashMap::new();
        let mut log_alpha = vec![];
        for i in 0..n {
            let m = sample(5, i);
            m.validate().unwrap_or_else(|e| panic!("material {i}: {e}: {m:?}"));
            *families.entry(m.family).or_insert(0) += 1;
            if let Some(l) = m.lobes.first() {
                log_alpha.push(l.alpha.ln());
            }
        }
        for family in Family::ALL {
            let count = families.get(&family).copied().unwrap_or(0);
            assert!(count > n / 10, "{family}: {count} of {n}");
        }
        let lo = log_alpha.iter().copied().fold(f64::INFINITY, f64::min).exp();
        let hi = log_alpha.iter().copied().fold(f64::NEG_INFINITY, f64::max).exp();
        assert!(lo < 0.01 && hi > 0.8, "alpha from {lo} to {hi}");
        let median_log = {
            log_alpha.sort_by(f64::total_cmp);
            log_alpha[log_alpha.len() / 2]
        };
        assert!(
            median_log.exp() > 0.03 && median_log.exp() < 0.3,
            "median alpha {}",
            median_log.exp()
        );
    }

    #[test]
    fn hsv_known_values() {
        assert_eq!(hsv_to_rgb(0.0, 1.0, 1.0), [1.0, 0.0, 0.0]);
        for (hsv, rgb) in [
            ([1.0 / 3.0, 1.0, 0.5], [0.0, 0.5, 0.0]),
            ([0.5, 0.0, 0.7], [0.7; 3]),
            ([0.75, 0.5, 0.8], [0.6, 0.4, 0.8]),
        ] {
            let c = hsv_to_rgb(hsv[0], hsv[1], hsv[2]);
            assert!((0..3).all(|i| (c[i] - rgb[i]).abs() < 1e-12), "{hsv:?}: {c:?}");
        }
    }
}

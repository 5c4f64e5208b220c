//! Energy conservation of a corpus material: no material reflects more light than arrives, from
//! any direction. Each part is normalised on its own (a Lambertian base, a microfacet lobe with
//! its Fresnel, a sheen, a retro-reflective lobe), but a sum of parts drawn independently can
//! exceed 1 (a bright base under a retro-reflective lobe, a sheen over a rough base, a base
//! under a lobe whose Fresnel rises at grazing angles). The sampler scales such a material's
//! weights until its largest directional albedo is at most [`ALBEDO_LIMIT`] ([`conserve`]).
//!
//! The albedo is [`crate::albedo`]'s, over half vectors, which resolves a sharp microfacet lobe.

use super::material::Material;
use crate::albedo::directional_albedo_in_steps;

/// Largest directional albedo a sampled material keeps (a little under 1, for the quadrature's
/// error).
pub const ALBEDO_LIMIT: f64 = 0.98;
/// Incidence angles (degrees) at which the albedo is checked: the largest is at grazing
/// incidence for every family that exceeds 1.
pub const ANGLES_DEG: [f64; 6] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0];
/// Midpoint steps in `u` (twice as many in the azimuth of `h`).
const STEPS: usize = 48;

/// The largest directional albedo of `material` over the channels and [`ANGLES_DEG`].
pub fn max_albedo(material: &Material) -> f64 {
    ANGLES_DEG
        .iter()
        .flat_map(|deg| {
            directional_albedo_in_steps(|a, b| material.eval(a, b), deg.to_radians(), STEPS)
        })
        .fold(0.0, f64::max)
}

/// `material` with its weights (base albedo, lobe tints, sheen and retro-reflective colours)
/// scaled until [`max_albedo`] is at most [`ALBEDO_LIMIT`]; a material within it is returned as
/// it is. A clear coat's own reflection is not scaled, so the scale is found again until it
/// holds.
pub fn conserve(mut material: Material) -> Material {
    for _ in 0..8 {
        let albedo = max_albedo(&material);
        if albedo <= ALBEDO_LIMIT {
            break;
        }
        material = material.scaled(ALBEDO_LIMIT / albedo);
    }
    material
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::checks::directional_albedo;
    use crate::corpus::diffuse::Diffuse;
    use crate::corpus::fresnel::Fresnel;
    use crate::corpus::material::Family;
    use crate::corpus::microfacet::{Distribution, Lobe};
    use crate::corpus::sampler::{sample, sample_family};

    #[test]
    fn the_half_vector_quadrature_agrees_with_the_outgoing_one() {
        let lambert = Diffuse::Lambertian { albedo: [0.8, 0.5, 0.2] };
        let lobe = Lobe {
            distribution: Distribution::Ggx,
            alpha: 0.3,
            fresnel: Fresnel::Dielectric { eta: 1.5 },
            tint: [1.0; 3],
        };
        type Brdf<'a> = &'a (dyn Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync);
        let parts: [Brdf; 2] = [&|a, b| lambert.eval(a, b), &|a, b| lobe.eval(a, b)];
        for theta in [0.0f64, 0.7, 1.3] {
            for f in parts {
                let h = directional_albedo_in_steps(f, theta, 96)[0];
                let o = directional_albedo(f, theta, 400)[0];
                assert!((h - o).abs() < 0.01 * o, "theta {theta}: {h} vs {o}");
            }
        }
    }

    /// Every sampled material reflects at most all the light from every direction (checked
    /// with a finer quadrature than the sampler's), and one within the limit is not touched.
    #[test]
    fn the_generator_conserves_energy() {
        let mut scaled = 0;
        for (seed, index) in (0..120).map(|i| (7, i)).chain((0..80).map(|i| (11, i))) {
            let m = sample(seed, index);
            let worst = ANGLES_DEG
                .iter()
                .flat_map(|d| directional_albedo_in_steps(|a, b| m.eval(a, b), d.to_radians(), 96))
                .fold(0.0, f64::max);
            assert!(worst <= 1.0, "seed {seed} material {index} ({}): albedo {worst}", m.family);
            scaled += usize::from(max_albedo(&m) > ALBEDO_LIMIT - 1e-3);
        }
        assert!(scaled > 0, "no material needed scaling: the check would not notice");
        // A metal lobe alone never reflects more than arrives: left as drawn.
        let metal = sample_family(Family::Metal, 7, 1);
        assert!(max_albedo(&metal) <= ALBEDO_LIMIT);
        assert_eq!(conserve(metal.clone()), metal);
    }
}

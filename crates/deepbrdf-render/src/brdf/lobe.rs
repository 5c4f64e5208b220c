//! A sampling proxy for tabulated BRDFs: a mixture of cosine-weighted sampling and two GGX
//! half-vector lobes (a core and a wider halo) whose roughnesses and weights are fitted to the
//! table. Measured metals have a sharp core with long tails (MERL's aluminium falls to 1% of its
//! peak within 2 degrees but keeps 0.4% at 3 degrees); one GGX lobe fitted to the core
//! under-samples the tails by orders of magnitude and leaves fireflies. The proxy only steers
//! where samples go (variance), never what they are worth: the renderer divides by its exact
//! pdf.

use super::{cosine_hemisphere_pdf, sample_cosine_hemisphere, Ggx};
use crate::geometry::Vec3;
use deepbrdf_data::merl::{grid, N_THETA_H};
use deepbrdf_data::MerlTable;
use std::f64::consts::PI;

/// Mixture of cosine sampling (probability `1 - specular_prob`) and GGX sampling, half of the
/// specular share with roughness `alpha` (the core), half with `halo_alpha >= alpha`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingLobe {
    pub alpha: f64,
    pub halo_alpha: f64,
    pub specular_prob: f64,
}

/// theta_d index of the profile the fit reads (about 10 degrees, away from MERL's unmeasurable
/// exact retro-reflection at theta_d = 0).
const FIT_THETA_D: usize = 10;
/// phi_d index of the profile the fit reads (phi_d = 90 degrees: valid for all theta_h).
const FIT_PHI_D: usize = 90;
/// Fraction of the peak (above the floor) whose crossing sets the halo's roughness.
const HALO_LEVEL: f64 = 0.01;

/// GGX roughness whose `D(t) / D(0)` equals `ratio` at angle `t`:
/// `D(t)/D(0) = (alpha^2 (1 + tan^2 t) / (alpha^2 + tan^2 t))^2`, so with `s = sqrt(ratio)`,
/// `alpha^2 = s tan^2 t / (1 + tan^2 t - s)`.
fn ggx_alpha_at(t: f64, ratio: f64) -> f64 {
    let tan2 = t.tan().powi(2);
    let s = ratio.sqrt();
    (s * tan2 / (1.0 + tan2 - s)).sqrt().clamp(1e-3, 1.0)
}

/// Angle at which `profile` (over the theta_h grid) first falls below `level`, linearly
/// interpolated between grid angles; `None` if it never does.
fn crossing(profile: &[f64], level: f64) -> Option<f64> {
    let i = profile.iter().position(|&v| v < level)?;
    if i == 0 {
        return Some(0.0);
    }
    let (t0, t1) = (grid::theta_h_of(i - 1), grid::theta_h_of(i));
    let (v0, v1) = (profile[i - 1], profile[i]);
    Some(t0 + (t1 - t0) * ((v0 - level) / (v0 - v1)).clamp(0.0, 1.0))
}

impl SamplingLobe {
    /// Pure cosine sampling.
    pub const DIFFUSE: Self = Self { alpha: 1.0, halo_alpha: 1.0, specular_prob: 0.0 };

    /// Fits the proxy to `table`'s theta_h profile at theta_d = 10 deg, phi_d = 90 deg (channel
    /// mean). The angle where the peak above the profile's floor halves gives the core's GGX
    /// `alpha`, the angle where it falls to [`HALO_LEVEL`] the halo's (see [`ggx_alpha_at`]).
    /// The specular share compares the lobe's albedo, about `4 pi alpha^2 (peak - floor)` (since
    /// `f(0) ~ F D(0) / 4` with `D(0) = 1 / (pi alpha^2)`), with the floor's, `pi floor`.
    pub fn fit(table: &MerlTable) -> Self {
        let profile: Vec<f64> = (0..N_THETA_H)
            .map(|h| {
                let rgb = table.rgb(h, FIT_THETA_D, FIT_PHI_D);
                rgb.iter().map(|&v| f64::from(v.max(0.0))).sum::<f64>() / 3.0
            })
            .collect();
        let peak = profile[0];
        let floor = profile.iter().copied().fold(f64::INFINITY, f64::min);
        if !(peak > floor * 1.05 && peak.is_finite()) {
            return Self::DIFFUSE;
        }
        let Some(t_half) = crossing(&profile, floor + 0.5 * (peak - floor)) else {
            return Self::DIFFUSE;
        };
        let alpha = ggx_alpha_at(t_half, 0.5);
        let halo_alpha = crossing(&profile, floor + HALO_LEVEL * (peak - floor))
            .map_or(1.0, |t| ggx_alpha_at(t, HALO_LEVEL))
            .max(alpha);
        let specular = 4.0 * PI * alpha * alpha * (peak - floor);
        let diffuse = PI * floor;
        let specular_prob = (specular / (specular + diffuse)).clamp(0.1, 0.9);
        Self { alpha, halo_alpha, specular_prob }
    }

    /// Draws `wi` for `wo` from `u` uniform in [0,1)^2; `None` below the horizon.
    #[inline]
    pub fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        if u[0] < self.specular_prob {
            // Core for the lower half of the specular share, halo for the upper half.
            let v = u[0] / self.specular_prob;
            let (alpha, v) =
                if v < 0.5 { (self.alpha, 2.0 * v) } else { (self.halo_alpha, 2.0 * v - 1.0) };
            let h = Ggx::sample_half_vector(alpha, [v, u[1]]);
            let wi = wo.reflect(h);
            (wi.z > 0.0).then_some(wi)
        } else {
            let v = (u[0] - self.specular_prob) / (1.0 - self.specular_prob);
            Some(sample_cosine_hemisphere([v, u[1]]))
        }
    }

    /// Solid-angle density of [`SamplingLobe::sample`].
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let spec = if self.specular_prob > 0.0 {
            0.5 * self.specular_prob
                * (Ggx::reflected_pdf(self.alpha, wi, wo)
                    + Ggx::reflected_pdf(self.halo_alpha, wi, wo))
        } else {
            0.0
        };
        spec + (1.0 - self.specular_prob) * cosine_hemisphere_pdf(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::grid;

    fn ggx_table(alpha: f64, f0: f64, diffuse: f64) -> MerlTable {
        MerlTable::from_fn(|h, d, _| {
            // Half-vector profile of a GGX lobe at theta_d's F = f0; enough for the fit.
            let th = grid::theta_h_of(h);
            let _ = d;
            let v = f0 * Ggx::distribution(alpha, th.cos()) / 4.0 + diffuse / PI;
            [v as f32; 3]
        })
    }

    #[test]
    fn fit_recovers_ggx_roughness() {
        for alpha in [0.02, 0.1, 0.3] {
            let lobe = SamplingLobe::fit(&ggx_table(alpha, 1.0, 0.0));
            assert!((lobe.alpha / alpha - 1.0).abs() < 0.15, "alpha {alpha}: {lobe:?}");
            assert_eq!(lobe.specular_prob, 0.9);
        }
        let lobe = SamplingLobe::fit(&ggx_table(0.1, 0.04, 0.8));
        assert!(lobe.specular_prob < 0.2, "{lobe:?}");
    }

    #[test]
    fn halo_follows_long_tails_and_sampling_matches_pdf() {
        // A sharp core plus a 10x wider tail peaking at a fifth of the core (20 x 1/100 of
        // D(0)): the halo roughness follows the tail.
        let t = MerlTable::from_fn(|h, _, _| {
            let c = grid::theta_h_of(h).cos();
            let v = Ggx::distribution(0.005, c) / 4.0 + 20.0 * Ggx::distribution(0.05, c) / 4.0;
            [v as f32; 3]
        });
        let lobe = SamplingLobe::fit(&t);
        // The core fit is biased up a little by the tail under its half maximum.
        assert!((lobe.alpha / 0.005 - 1.0).abs() < 0.3, "{lobe:?}");
        assert!(lobe.halo_alpha > 4.0 * lobe.alpha, "{lobe:?}");
        struct Proxy(SamplingLobe);
        impl crate::brdf::Brdf for Proxy {
            fn eval(&self, wi: Vec3, wo: Vec3) -> crate::brdf::Rgb {
                [Ggx::reflected_pdf(0.3, wi, wo) + 0.1; 3]
            }
            fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
                self.0.sample(wo, u)
            }
            fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
                self.0.pdf(wi, wo)
            }
        }
        let mixed = SamplingLobe { alpha: 0.1, halo_alpha: 0.4, specular_prob: 0.6 };
        let (s, u) = crate::brdf::tests::check_sampling(
            &Proxy(mixed),
            Vec3::from_spherical(0.5, 0.0),
            100_000,
        );
        assert!((s - u).abs() < 0.03 * u, "sampled {s} uniform {u}");
    }

    #[test]
    fn diffuse_table_gives_cosine_sampling() {
        let t = MerlTable::from_fn(|_, _, _| [0.2; 3]);
        assert_eq!(SamplingLobe::fit(&t), SamplingLobe::DIFFUSE);
    }
}

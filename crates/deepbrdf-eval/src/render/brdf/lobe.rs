//! A sampling proxy for tabulated BRDFs: a mixture of cosine-weighted and GGX half-vector
//! sampling whose roughness and mixture weight are fitted to the table. It only steers where
//! samples go (variance), never what they are worth (the renderer divides by its exact pdf).

use super::{cosine_hemisphere_pdf, sample_cosine_hemisphere, Ggx};
use crate::render::geometry::Vec3;
use deepbrdf_data::merl::{grid, N_THETA_H};
use deepbrdf_data::MerlTable;
use std::f64::consts::PI;

/// Mixture of cosine sampling (probability `1 - specular_prob`) and GGX sampling of roughness
/// `alpha` (probability `specular_prob`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingLobe {
    pub alpha: f64,
    pub specular_prob: f64,
}

/// theta_d index of the profile the fit reads (about 10 degrees, away from MERL's unmeasurable
/// exact retro-reflection at theta_d = 0).
const FIT_THETA_D: usize = 10;
/// phi_d index of the profile the fit reads (phi_d = 90 degrees: valid for all theta_h).
const FIT_PHI_D: usize = 90;

impl SamplingLobe {
    /// Pure cosine sampling.
    pub const DIFFUSE: Self = Self { alpha: 1.0, specular_prob: 0.0 };

    /// Fits the proxy to `table`'s theta_h profile at theta_d = 10 deg, phi_d = 90 deg (channel
    /// mean). The half-maximum angle of the peak above the profile's floor gives GGX's `alpha`
    /// (for GGX `D(t)/D(0) = 1/2` at `alpha^2 = tan^2 t / (sqrt 2 (1 + tan^2 t) - 1)`); the
    /// mixture weight compares the lobe's albedo, about `4 pi alpha^2 (peak - floor)` (since
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
        let half = floor + 0.5 * (peak - floor);
        let Some(i) = profile.iter().position(|&v| v < half) else {
            return Self::DIFFUSE;
        };
        // Linear interpolation of the crossing between grid angles i-1 and i.
        let (t0, t1) = (grid::theta_h_of(i - 1), grid::theta_h_of(i));
        let (v0, v1) = (profile[i - 1], profile[i]);
        let t = t0 + (t1 - t0) * ((v0 - half) / (v0 - v1)).clamp(0.0, 1.0);
        let tan2 = t.tan().powi(2);
        let alpha = (tan2 / (2f64.sqrt() * (1.0 + tan2) - 1.0)).sqrt().clamp(1e-3, 1.0);
        let specular = 4.0 * PI * alpha * alpha * (peak - floor);
        let diffuse = PI * floor;
        let specular_prob = (specular / (specular + diffuse)).clamp(0.1, 0.9);
        Self { alpha, specular_prob }
    }

    /// Draws `wi` for `wo` from `u` uniform in [0,1)^2; `None` below the horizon.
    #[inline]
    pub fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        if u[0] < self.specular_prob {
            let h = Ggx::sample_half_vector(self.alpha, [u[0] / self.specular_prob, u[1]]);
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
            self.specular_prob * Ggx::reflected_pdf(self.alpha, wi, wo)
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
    fn diffuse_table_gives_cosine_sampling() {
        let t = MerlTable::from_fn(|_, _, _| [0.2; 3]);
        assert_eq!(SamplingLobe::fit(&t), SamplingLobe::DIFFUSE);
    }
}

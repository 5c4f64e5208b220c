//! Directional albedo, `a(wi) = integral f(wi, wo) cos(theta_o) dwo`: the share of the light
//! arriving from `wi` that a material reflects, for a MERL table ([`directional_albedo`]) or any
//! BRDF ([`directional_albedo_of`]) by one quadrature, so two BRDFs compared on it (a table and
//! its edit, a table and an exported file, the parts of a generated material) are compared on the
//! same directions.
//!
//! The integral is taken over half vectors (`wo` the mirror of `wi` about `h`,
//! `dwo = 4 <wi, h> dwh`), midpoint steps in `u` with `theta_h = u^2 pi / 2` (the MERL grid's
//! square-root warp) and twice as many in the azimuth of `h`: a sharp microfacet lobe lives at
//! `h` near the normal, where the warp's steps are finest, so a mirror-like table is integrated
//! as finely as the grid resolves it. Deterministic.

use crate::merl::coords::direction;
use crate::MerlTable;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Midpoint steps in `u` of [`directional_albedo_of`] (twice as many in the azimuth).
pub const STEPS: usize = 96;

/// Directional albedo of the BRDF `f(wi, wo)` (per channel, 1/sr) for light arriving at polar
/// angle `theta_i` (radians, azimuth 0), with [`STEPS`] steps.
pub fn directional_albedo_of(
    f: impl Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync,
    theta_i: f64,
) -> [f64; 3] {
    directional_albedo_in_steps(f, theta_i, STEPS)
}

/// [`directional_albedo_of`] with `n` steps in `u` and `2 n` in the azimuth of `h`.
pub fn directional_albedo_in_steps(
    f: impl Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync,
    theta_i: f64,
    n: usize,
) -> [f64; 3] {
    let wi = direction(theta_i, 0.0);
    let (du, dphi) = (1.0 / n as f64, PI / n as f64);
    let rows: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|a| {
            let u = (a as f64 + 0.5) * du;
            let theta_h = u * u * PI / 2.0;
            // d(theta_h) = pi u du; d(omega_h) = sin(theta_h) d(theta_h) d(phi).
            let area = theta_h.sin() * PI * u * du * dphi;
            let mut sum = [0.0; 3];
            for b in 0..2 * n {
                let h = direction(theta_h, (b as f64 + 0.5) * dphi);
                let cos = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2];
                let wo =
                    [2.0 * cos * h[0] - wi[0], 2.0 * cos * h[1] - wi[1], 2.0 * cos * h[2] - wi[2]];
                if cos <= 0.0 || wo[2] <= 0.0 {
                    continue;
                }
                let v = f(wi, wo);
                let w = wo[2] * 4.0 * cos * area;
                for c in 0..3 {
                    sum[c] += v[c] * w;
                }
            }
            sum
        })
        .collect();
    std::array::from_fn(|c| rows.iter().map(|r| r[c]).sum())
}

/// Directional albedo of `table` (read as the renderer reads it, interpolated) for light
/// arriving at polar angle `theta_i` (radians), per channel.
pub fn directional_albedo(table: &MerlTable, theta_i: f64) -> [f64; 3] {
    directional_albedo_of(|wi, wo| table.lookup_interpolated(wi, wo).map(f64::from), theta_i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::analytic::{ggx, lambertian_table, tabulate, Ggx};

    #[test]
    fn a_lambertian_table_reflects_its_albedo_at_every_angle() {
        let table = lambertian_table([0.6, 0.4, 0.2]);
        for deg in [0.0f64, 30.0, 60.0, 85.0] {
            let a = directional_albedo(&table, deg.to_radians());
            for (c, want) in [0.6, 0.4, 0.2].into_iter().enumerate() {
                assert!((a[c] - want).abs() < 3e-3 * want, "{deg} deg, channel {c}: {a:?}");
            }
        }
    }

    /// A mirror-like GGX table (alpha 0.01) integrates to what its analytic BRDF does: the
    /// warp resolves the spike.
    #[test]
    fn a_sharp_lobe_is_integrated_as_its_table_resolves_it() {
        let g = Ggx { alpha: 0.01, f0: [0.9; 3], diffuse: [0.0; 3] };
        let table = tabulate(|wi, wo| ggx(&g, wi, wo));
        for deg in [0.0f64, 30.0, 60.0] {
            let t = directional_albedo(&table, deg.to_radians())[0];
            let a = directional_albedo_in_steps(|wi, wo| ggx(&g, wi, wo), deg.to_radians(), 400)[0];
            assert!((t - a).abs() < 0.03 * a, "{deg} deg: table {t}, analytic {a}");
        }
    }
}

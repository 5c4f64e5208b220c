//! Directional albedo, `a(wi) = integral f_r(wi, wo) cos(theta_o) dwo`: the share of light from
//! `wi` that a material reflects. An exported RGL file must keep it (energy lost or gained at
//! grazing angles is what a renderer shows on floors and rims), so it is computed for a MERL
//! table and for an RGL evaluator by the same quadrature and compared.
//!
//! The quadrature is a midpoint rule over `(cos(theta_o), phi_o)`, in which `cos(theta_o) dwo`
//! is uniform: [`RINGS`] rings and [`AZIMUTHS`] azimuths over the half circle (isotropic
//! materials are mirror-symmetric in azimuth).

use super::evaluate::RglBrdf;
use crate::merl::coords::direction;
use crate::MerlTable;
use std::f64::consts::PI;

/// Rings in `cos^2(theta_o)` (uniform in projected solid angle).
pub const RINGS: usize = 256;
/// Azimuths over `[0, pi]`.
pub const AZIMUTHS: usize = 256;

/// The quadrature's directions `wo` for light arriving from polar angle `theta_i` (azimuth 0),
/// each standing for an equal share `pi / (RINGS * AZIMUTHS)` of projected solid angle, with the
/// incident direction.
fn nodes(theta_i: f64) -> ([f64; 3], impl Iterator<Item = [f64; 3]>) {
    let wi = direction(theta_i, 0.0);
    let wo = (0..RINGS * AZIMUTHS).map(|k| {
        let (ring, azimuth) = (k / AZIMUTHS, k % AZIMUTHS);
        // Uniform in sin^2(theta_o) is uniform in cos(theta_o) d(omega) over the hemisphere.
        let sin2 = (ring as f64 + 0.5) / RINGS as f64;
        let phi = (azimuth as f64 + 0.5) / AZIMUTHS as f64 * PI;
        direction(sin2.sqrt().asin(), phi)
    });
    (wi, wo)
}

/// The RGB directional albedo of `table` (read as the renderer reads it, interpolated, clamped
/// at 0) for light from polar angle `theta_i` (radians).
pub fn table_albedo(table: &MerlTable, theta_i: f64) -> [f64; 3] {
    let (wi, wo) = nodes(theta_i);
    let mut sum = [0.0; 3];
    for wo in wo {
        let f = table.lookup_interpolated(wi, wo);
        for c in 0..3 {
            sum[c] += f64::from(f[c].max(0.0));
        }
    }
    sum.map(|s| s * PI / (RINGS * AZIMUTHS) as f64)
}

/// The RGB directional albedo of an RGL evaluator for light from polar angle `theta_i`
/// (radians): its `f_r cos(theta_o)` divided by `cos(theta_o)` on the same nodes.
pub fn file_albedo(brdf: &RglBrdf, theta_i: f64) -> [f64; 3] {
    let (wi, wo) = nodes(theta_i);
    let mut sum = [0.0; 3];
    for wo in wo {
        let e = brdf.eval_cos(wi.map(|v| v as f32), wo.map(|v| v as f32));
        for c in 0..3 {
            sum[c] += f64::from(e[c]) / wo[2];
        }
    }
    sum.map(|s| s * PI / (RINGS * AZIMUTHS) as f64)
}

/// The ratio of the albedos' Rec. 709 luminances, file over table, at each of `angles`
/// (degrees): 1 where the file reflects as much light as the table.
pub fn albedo_ratios(table: &MerlTable, brdf: &RglBrdf, angles: &[f64]) -> Vec<f64> {
    angles
        .iter()
        .map(|deg| {
            let t = super::export::luminance(table_albedo(table, deg.to_radians()));
            let f = super::export::luminance(file_albedo(brdf, deg.to_radians()));
            f / t
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::analytic::lambertian_table;

    #[test]
    fn a_lambertian_table_reflects_its_albedo_at_every_angle() {
        let table = lambertian_table([0.6, 0.4, 0.2]);
        for deg in [0.0f64, 30.0, 60.0, 85.0] {
            let a = table_albedo(&table, deg.to_radians());
            for (c, want) in [0.6, 0.4, 0.2].into_iter().enumerate() {
                assert!((a[c] - want).abs() < 2e-3 * want, "{deg} deg, channel {c}: {a:?}");
            }
        }
    }
}

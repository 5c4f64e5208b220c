//! Analytic BRDFs and tables tabulated from them, for tests in this crate and others (a renderer
//! can check itself against a closed form): a Lambertian constant and the GGX microfacet lobe of
//! [`crate::ggx`].

use crate::merl::coords::HalfDiff;
use crate::merl::grid::{phi_d_of, theta_d_of, theta_h_of};
use crate::merl::MerlTable;
use std::f64::consts::PI;

pub use crate::ggx::{ggx, Ggx};

/// Tabulates `brdf(wi, wo) -> rgb` (1/sr) on the MERL grid: each valid cell gets the value at
/// its sample angles ([`crate::merl::grid`]) with phi_h = 0, as the NBRDF tabulation does.
pub fn tabulate(brdf: impl Fn([f64; 3], [f64; 3]) -> [f64; 3]) -> MerlTable {
    MerlTable::from_fn(|h, d, p| {
        let angles = HalfDiff {
            theta_h: theta_h_of(h),
            phi_h: 0.0,
            theta_d: theta_d_of(d),
            phi_d: phi_d_of(p),
        };
        let (wi, wo) = angles.to_dirs();
        brdf(wi, wo).map(|v| v as f32)
    })
}

/// A Lambertian table: albedo / pi in every valid cell.
pub fn lambertian_table(albedo: [f64; 3]) -> MerlTable {
    let rgb = albedo.map(|a| (a / PI) as f32);
    MerlTable::from_fn(|_, _, _| rgb)
}

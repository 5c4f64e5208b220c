//! Whether an RGL file reflects as much light as the table it was exported from: the
//! directional albedo ([`crate::albedo`]) of the file's evaluator against the table's, on the
//! same quadrature directions. Energy lost or gained at grazing angles is what a renderer shows
//! on floors and rims.

use super::evaluate::RglBrdf;
use super::export::luminance;
use crate::albedo::{directional_albedo, directional_albedo_of};
use crate::MerlTable;

/// The RGB directional albedo of an RGL evaluator for light from polar angle `theta_i`
/// (radians): its `f_r cos(theta_o)` divided by `cos(theta_o)`.
pub fn file_albedo(brdf: &RglBrdf, theta_i: f64) -> [f64; 3] {
    let f = |wi: [f64; 3], wo: [f64; 3]| {
        let e = brdf.eval_cos(wi.map(|v| v as f32), wo.map(|v| v as f32));
        e.map(|v| f64::from(v) / wo[2])
    };
    directional_albedo_of(f, theta_i)
}

/// The ratio of the albedos' Rec. 709 luminances, file over table, at each of `angles`
/// (degrees): 1 where the file reflects as much light as the table.
pub fn albedo_ratios(table: &MerlTable, brdf: &RglBrdf, angles: &[f64]) -> Vec<f64> {
    angles
        .iter()
        .map(|deg| {
            let t = luminance(directional_albedo(table, deg.to_radians()));
            luminance(file_albedo(brdf, deg.to_radians())) / t
        })
        .collect()
}

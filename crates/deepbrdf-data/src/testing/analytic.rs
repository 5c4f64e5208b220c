//! Analytic BRDFs and tables tabulated from them, for tests in this crate and others (a renderer
//! can check itself against a closed form): a Lambertian constant and the GGX microfacet lobe of
//! [`crate::ggx`], tabulated by [`crate::corpus::tabulate`]; the corpus ([`crate::corpus`]) has
//! the other analytic models.

use crate::merl::MerlTable;
use std::f64::consts::PI;

pub use crate::ggx::{ggx, Ggx};

/// [`crate::corpus::tabulate`] for tests: panics if a value is not finite (a test's analytic
/// BRDF is finite by construction).
pub fn tabulate(brdf: impl Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync) -> MerlTable {
    crate::corpus::tabulate(brdf).unwrap_or_else(|e| panic!("{e}"))
}

/// A Lambertian table: albedo / pi in every valid cell.
pub fn lambertian_table(albedo: [f64; 3]) -> MerlTable {
    let rgb = albedo.map(|a| (a / PI) as f32);
    MerlTable::from_fn(|_, _, _| rgb)
}

//! Tabulating an RGL measurement onto the MERL grid: each valid cell ([`grid::valid_mask`]) gets
//! the evaluator's value at its bin centre ([`grid::theta_h_of`], [`grid::theta_d_of`],
//! [`grid::phi_d_of`], phi_h = 0: the measurement is isotropic), by the cell rule of
//! [`RglBrdf::reciprocal`] (or, to measure what that choice changes, [`CellRule::MeanOfOrderings`]).
//! Invalid cells get [`crate::merl::INVALID_VALUE`]. One theta_h row of the grid per rayon task;
//! each cell is computed independently, so the table is the same bit for bit at any thread count.

use super::RglBrdf;
use crate::error::{DataError, Result};
use crate::merl::coords::HalfDiff;
use crate::merl::grid::ROW;
use crate::merl::{grid, MerlTable, N_PHI_D, N_THETA_D};

/// Version of the RGL tabulation. Bump it whenever the values this module (or the evaluator)
/// produces change, so cached conversions are recomputed.
pub const RGL_TABULATOR_VERSION: u32 = 1;

/// How a MERL cell, which stands for both orderings of its two directions, gets its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellRule {
    /// `(e(a, b) + e(b, a)) / (cos a + cos b)`: [`RglBrdf::reciprocal`], the default.
    CosineWeighted,
    /// `(e(a, b) / cos b + e(b, a) / cos a) / 2`: [`RglBrdf::mean_of_orderings`].
    MeanOfOrderings,
}

/// The MERL table of `brdf` (reflectance in 1/sr) under the default rule.
pub fn tabulate(brdf: &RglBrdf) -> Result<MerlTable> {
    tabulate_with(brdf, CellRule::CosineWeighted)
}

/// The MERL table of `brdf` under `rule`.
pub fn tabulate_with(brdf: &RglBrdf, rule: CellRule) -> Result<MerlTable> {
    let mask = grid::valid_mask();
    MerlTable::from_par_rows(|i, [r, g, b]| {
        let theta_h = grid::theta_h_of(i);
        for j in 0..N_THETA_D {
            let theta_d = grid::theta_d_of(j);
            for k in 0..N_PHI_D {
                let local = j * N_PHI_D + k;
                if !mask[i * ROW + local] {
                    continue;
                }
                let angles = HalfDiff { theta_h, phi_h: 0.0, theta_d, phi_d: grid::phi_d_of(k) };
                let (wi, wo) = angles.to_dirs();
                let rgb = match rule {
                    CellRule::CosineWeighted => brdf.reciprocal(wi, wo),
                    CellRule::MeanOfOrderings => brdf.mean_of_orderings(wi, wo),
                };
                r[local] = rgb[0];
                g[local] = rgb[1];
                b[local] = rgb[2];
            }
        }
    })
    .map_err(|e| {
        DataError::Invalid(format!("{}: tabulates to an invalid table: {e}", brdf.description()))
    })
}

/// What choosing one [`CellRule`] over the other changes in a table: over the cells valid in
/// both, the mean and the 99th percentile of `|a - b| / max(a, b)` (channel by channel, cells
/// where both are 0 left out), and the largest absolute difference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleDifference {
    pub mean_relative: f64,
    pub p99_relative: f64,
    pub max_absolute: f64,
}

/// Compares two tables of the same material cell by cell (see [`RuleDifference`]).
pub fn rule_difference(a: &MerlTable, b: &MerlTable) -> RuleDifference {
    let mut rel: Vec<f64> = a
        .values()
        .iter()
        .zip(b.values())
        .filter(|(x, y)| **x >= 0.0 && **y >= 0.0 && (**x > 0.0 || **y > 0.0))
        .map(|(&x, &y)| f64::from((x - y).abs() / x.max(y)))
        .collect();
    let max_absolute = a
        .values()
        .iter()
        .zip(b.values())
        .filter(|(x, y)| **x >= 0.0 && **y >= 0.0)
        .map(|(&x, &y)| f64::from((x - y).abs()))
        .fold(0.0, f64::max);
    if rel.is_empty() {
        return RuleDifference { mean_relative: 0.0, p99_relative: 0.0, max_absolute };
    }
    let mean_relative = rel.iter().sum::<f64>() / rel.len() as f64;
    rel.sort_by(f64::total_cmp);
    let p99_relative = rel[(rel.len() - 1) * 99 / 100];
    RuleDifference { mean_relative, p99_relative, max_absolute }
}

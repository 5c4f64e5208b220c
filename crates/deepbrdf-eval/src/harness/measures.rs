//! Error measures between an original table and its reconstruction, each over the cells valid
//! in the original only (invalid cells carry no measurement).

use crate::error::{EvalError, Result};
use crate::ipca;
use crate::median_reference::MedianReference;
use deepbrdf_data::merl::{CELLS, VALUES};
use deepbrdf_data::MerlTable;
use rayon::prelude::*;
use std::fmt;
use std::str::FromStr;

/// A reconstruction error measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Measure {
    /// Mean squared error in the space of the paper's eq. (1),
    /// `ln((rho + eps)/(rho_ref + eps) + 1)`, the reference being the per-value median of the
    /// run's (or fold's) training tables: the space DeepBRDF is trained in, the common yardstick.
    MappedMse,
    /// Root mean square of `(rho - rho_hat) cos(theta_i) cos(theta_o)`, linear reflectance
    /// (1/sr) weighted by the cosines as in Nielsen et al. 2015's mapping.
    CosRmse,
}

impl Measure {
    /// All measures, in table order.
    pub const ALL: [Measure; 2] = [Measure::MappedMse, Measure::CosRmse];

    /// Machine name, used in CSV files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::MappedMse => "mapped_mse",
            Self::CosRmse => "cos_rmse",
        }
    }

    /// Human label for plots and tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::MappedMse => "MSE in eq. (1) mapped space",
            Self::CosRmse => "cosine-weighted RMSE (1/sr)",
        }
    }
}

impl fmt::Display for Measure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Measure {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            EvalError::Invalid(format!("unknown measure '{s}' (mapped_mse, cos_rmse)"))
        })
    }
}

/// What the measures compare against: the training median of eq. (1) and the cosine weights.
pub struct Yardstick {
    reference: MedianReference,
    cos_weight: Vec<f32>,
}

/// One original table prepared for repeated comparisons (its mapping and mask computed once).
pub struct Original<'a> {
    table: &'a MerlTable,
    mask: Vec<bool>,
    mapped: Vec<f32>,
}

impl Yardstick {
    /// The yardstick of a training set: eq. (1)'s reference is their per-value median.
    pub fn from_training(train: &[&MerlTable]) -> Result<Self> {
        let reference = MedianReference::from_tables(train)?;
        let cos_weight =
            (0..CELLS).into_par_iter().map(|c| ipca::cos_product(c).max(0.0) as f32).collect();
        Ok(Self { reference, cos_weight })
    }

    /// Prepares `table` for comparisons.
    pub fn original<'a>(&self, table: &'a MerlTable) -> Original<'a> {
        Original { table, mask: table.mask(), mapped: self.reference.map(table) }
    }

    /// All `measures` of `recon` against `original`, in the given order.
    pub fn measure(
        &self,
        original: &Original,
        recon: &MerlTable,
        measures: &[Measure],
    ) -> Result<Vec<f64>> {
        if recon.values().len() != VALUES {
            return Err(EvalError::Invalid("reconstruction is not a full table".into()));
        }
        // A reconstruction invalid where the original is valid counts as reflectance 0 there.
        let patched;
        let recon = if (0..CELLS).any(|c| original.mask[c] && !recon.is_valid(c)) {
            let mut values = recon.values().to_vec();
            for c in 0..CELLS {
                if original.mask[c] && !recon.is_valid(c) {
                    for ch in 0..3 {
                        values[ch * CELLS + c] = values[ch * CELLS + c].max(0.0);
                    }
                }
            }
            patched = MerlTable::from_values(values)?;
            &patched
        } else {
            recon
        };
        let valid = original.mask.iter().filter(|&&m| m).count();
        if valid == 0 {
            return Err(EvalError::Invalid("the original table has no valid cell".into()));
        }
        let count = (3 * valid) as f64;
        let mut out = Vec::with_capacity(measures.len());
        for m in measures {
            let value = match m {
                Measure::MappedMse => {
                    let mapped = self.reference.map(recon);
                    sum_over_valid(&original.mask, |i| {
                        let d = f64::from(original.mapped[i]) - f64::from(mapped[i]);
                        d * d
                    }) / count
                }
                Measure::CosRmse => {
                    let (a, b) = (original.table.values(), recon.values());
                    (sum_over_valid(&original.mask, |i| {
                        let w = f64::from(self.cos_weight[i % CELLS]);
                        let d = (f64::from(a[i]) - f64::from(b[i])) * w;
                        d * d
                    }) / count)
                        .sqrt()
                }
            };
            out.push(value);
        }
        Ok(out)
    }
}

/// Sum of `f(i)` over every value index `i` (all three channels) whose cell is valid in `mask`.
fn sum_over_valid(mask: &[bool], f: impl Fn(usize) -> f64 + Sync) -> f64 {
    (0..3)
        .into_par_iter()
        .map(|ch| {
            mask.par_iter()
                .enumerate()
                .filter(|(_, &m)| m)
                .map(|(c, _)| f(ch * CELLS + c))
                .sum::<f64>()
        })
        .sum()
}

//! The per-value median reference of the paper's eq. (1). The data layer's
//! `deepbrdf_data::mapping` (H1) is the one to use; until it lands this module provides the same
//! names (`EPSILON`, `log_relative`, `MedianReference::{from_tables, values, map}`) with the same
//! definitions, so replacing it is `pub use deepbrdf_data::mapping::{...}`.

use deepbrdf_data::merl::{CELLS, VALUES};
use deepbrdf_data::MerlTable;
use rayon::prelude::*;

/// eps of eq. (1).
pub const EPSILON: f64 = 1e-3;

/// Values per parallel work item.
const CHUNK: usize = 16 * 1024;

/// Eq. (1) for one value: `ln((rho + eps) / (rho_ref + eps) + 1)`.
#[inline]
pub fn log_relative(rho: f64, rho_ref: f64) -> f64 {
    ((rho + EPSILON) / (rho_ref + EPSILON)).ln_1p()
}

/// Per-value median of a set of tables (valid values only).
pub struct MedianReference {
    values: Vec<f32>,
}

impl MedianReference {
    /// The median over `tables` of each value over the tables where its cell is valid (mean of
    /// the two middle ones for an even count; 0 where no table is valid).
    pub fn from_tables(tables: &[&MerlTable]) -> deepbrdf_data::Result<Self> {
        if tables.is_empty() {
            return Err(deepbrdf_data::DataError::Invalid("median of no tables".into()));
        }
        let mut values = vec![0f32; VALUES];
        values.par_chunks_mut(CHUNK).enumerate().for_each(|(b, out)| {
            let mut buf = Vec::with_capacity(tables.len());
            for (o, i) in out.iter_mut().zip(b * CHUNK..) {
                buf.clear();
                buf.extend(tables.iter().filter(|t| t.is_valid(i % CELLS)).map(|t| t.values()[i]));
                *o = median(&mut buf);
            }
        });
        Ok(Self { values })
    }

    /// The reference values, VALUES long, MERL order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Eq. (1) on every value; invalid cells map to 0.
    pub fn map(&self, table: &MerlTable) -> Vec<f32> {
        let v = table.values();
        let mut out = vec![0f32; VALUES];
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(b, chunk)| {
            for (o, i) in chunk.iter_mut().zip(b * CHUNK..) {
                if table.is_valid(i % CELLS) {
                    *o = log_relative(f64::from(v[i]), f64::from(self.values[i])) as f32;
                }
            }
        });
        out
    }
}

/// Median of `values` (reordered); the mean of the two middle ones for an even count; 0 for none.
fn median(values: &mut [f32]) -> f32 {
    let n = values.len();
    if n == 0 {
        return 0.0;
    }
    let (lower, upper, _) = values.select_nth_unstable_by(n / 2, f32::total_cmp);
    let upper = *upper;
    if n % 2 == 1 {
        upper
    } else {
        let below = lower.iter().copied().max_by(f32::total_cmp).unwrap_or(upper);
        (0.5 * (f64::from(below) + f64::from(upper))) as f32
    }
}

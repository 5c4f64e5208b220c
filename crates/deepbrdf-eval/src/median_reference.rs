//! The per-value median reference of the paper's eq. (1). The data layer's
//! `deepbrdf_data::mapping::MedianReference` (H3) is the one to use; until it lands this module
//! provides the same three calls so the harness builds. Replace the body with
//! `pub use deepbrdf_data::mapping::MedianReference;` when it exists.

use deepbrdf_data::merl::{CELLS, VALUES};
use deepbrdf_data::MerlTable;
use rayon::prelude::*;

/// eps of eq. (1).
const EPSILON: f64 = 1e-3;

/// Per-value median of a set of tables (valid values only).
pub struct MedianReference {
    values: Vec<f32>,
}

impl MedianReference {
    /// The median over `tables` of each value (mean of the two middle ones for an even count).
    pub fn from_tables(tables: &[&MerlTable]) -> deepbrdf_data::Result<Self> {
        if tables.is_empty() {
            return Err(deepbrdf_data::DataError::Invalid("median of no tables".into()));
        }
        let mut values = vec![0f32; VALUES];
        values.par_chunks_mut(4096).enumerate().for_each(|(b, out)| {
            let mut buf = Vec::with_capacity(tables.len());
            for (o, i) in out.iter_mut().zip(b * 4096..) {
                buf.clear();
                buf.extend(tables.iter().map(|t| t.values()[i]).filter(|v| *v >= 0.0));
                if buf.is_empty() {
                    continue;
                }
                buf.sort_by(f32::total_cmp);
                let n = buf.len();
                *o = if n % 2 == 1 { buf[n / 2] } else { 0.5 * (buf[n / 2 - 1] + buf[n / 2]) };
            }
        });
        Ok(Self { values })
    }

    /// The reference values, VALUES long, MERL order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Eq. (1): `ln((rho + eps)/(rho_ref + eps) + 1)`; invalid cells map to 0.
    pub fn map(&self, table: &MerlTable) -> Vec<f32> {
        let v = table.values();
        let mut out = vec![0f32; VALUES];
        out.par_chunks_mut(CELLS).enumerate().for_each(|(c, o)| {
            for cell in 0..CELLS {
                if table.is_valid(cell) {
                    let i = c * CELLS + cell;
                    let r = (f64::from(v[i]) + EPSILON) / (f64::from(self.values[i]) + EPSILON);
                    o[cell] = (r + 1.0).ln() as f32;
                }
            }
        });
        out
    }
}

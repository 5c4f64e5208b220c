//! The log-relative mapping of eq. (1) (Hu et al. 2020, §3.1, after Nielsen et al. 2015):
//! `rho' = ln((rho + eps) / (rho_ref + eps) + 1)` with `eps = 1e-3`, where the reference BRDF
//! `rho_ref` is the median over a training set of each value, i.e. of each
//! (theta_h, theta_d, phi_d) cell and colour channel ([`MedianReference`]).
//!
//! The mapping compresses the high dynamic range of measured BRDFs for the network; its inverse
//! ([`MedianReference::unmap`]) is exact up to f32 rounding of the mapped value.
//!
//! A reference is saved and reloaded with the model it belongs to ([`file`]: its format).

pub mod file;

use crate::error::{DataError, Result};
use crate::merl::{MerlTable, CELLS, INVALID_VALUE, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
use rayon::prelude::*;

/// eps of eq. (1): a small constant that avoids division by zero.
pub const EPSILON: f64 = 1e-3;

/// Values per parallel work item.
const CHUNK: usize = 16 * 1024;

/// Eq. (1) for one value: `ln((rho + eps) / (rho_ref + eps) + 1)`.
#[inline]
pub fn log_relative(rho: f64, rho_ref: f64) -> f64 {
    ((rho + EPSILON) / (rho_ref + EPSILON)).ln_1p()
}

/// The inverse of [`log_relative`]: `(exp(mapped) - 1) (rho_ref + eps) - eps`, not clamped.
#[inline]
pub fn inverse_log_relative(mapped: f64, rho_ref: f64) -> f64 {
    mapped.exp_m1() * (rho_ref + EPSILON) - EPSILON
}

/// The reference BRDF of eq. (1): one non-negative value per cell and channel ([`VALUES`] values,
/// channel-major, each channel in MERL's file order), the median over a training set.
#[derive(Clone, PartialEq)]
pub struct MedianReference {
    values: Vec<f32>,
}

impl std::fmt::Debug for MedianReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MedianReference {{ {} values }}", self.values.len())
    }
}

impl MedianReference {
    /// The per-value median over `tables` (§3.1: "the median value for each
    /// (theta_h, theta_d, phi_d), over the entire MERL dataset"), computed in parallel.
    ///
    /// For each cell and channel, the median is taken over the tables in which the cell is valid
    /// ([`MerlTable::is_valid`]); for an even count it is the mean of the two middle values. A
    /// cell that is valid in no table gets the reference 0 (it is never mapped: invalid cells map
    /// to 0 whatever the reference).
    pub fn from_tables(tables: &[&MerlTable]) -> Result<Self> {
        Self::from_remainders(tables, &vec![[0.0; 3]; tables.len()])
    }

    /// The per-value median of what is left of each table once a constant per channel is
    /// taken off, `tables[t] - less[t]`, floored at 0 (a reference is non-negative): the
    /// reference of the specular parts of a diffuse-specular separation, `less` the diffuse
    /// BRDFs `albedo / pi` (Sun et al. 2018). Otherwise as [`MedianReference::from_tables`].
    pub fn from_remainders(tables: &[&MerlTable], less: &[[f32; 3]]) -> Result<Self> {
        if less.len() != tables.len() {
            return Err(DataError::Invalid(format!(
                "{} tables but {} constants to take off them",
                tables.len(),
                less.len()
            )));
        }
        if tables.is_empty() {
            return Err(DataError::Invalid("the median reference needs at least one table".into()));
        }
        let per_cell: Vec<[f32; 3]> = (0..CELLS)
            .into_par_iter()
            .with_min_len(1024)
            .map_init(
                || [Vec::with_capacity(tables.len()), Vec::new(), Vec::new()],
                |bufs, cell| {
                    for b in bufs.iter_mut() {
                        b.clear();
                    }
                    for (t, off) in tables.iter().zip(less) {
                        if t.is_valid(cell) {
                            let v = t.values();
                            for (c, b) in bufs.iter_mut().enumerate() {
                                b.push(v[c * CELLS + cell] - off[c]);
                            }
                        }
                    }
                    let mut out = [0f32; 3];
                    for (o, b) in out.iter_mut().zip(bufs.iter_mut()) {
                        *o = median(b).max(0.0);
                    }
                    out
                },
            )
            .collect();
        let mut values = vec![0f32; VALUES];
        for (c, channel) in values.chunks_exact_mut(CELLS).enumerate() {
            for (v, rgb) in channel.iter_mut().zip(&per_cell) {
                *v = rgb[c];
            }
        }
        Ok(Self { values })
    }

    /// Wraps precomputed reference values: [`VALUES`] long, finite and non-negative.
    pub fn from_values(values: Vec<f32>) -> Result<Self> {
        if values.len() != VALUES {
            return Err(DataError::Invalid(format!(
                "a median reference has {VALUES} values, got {}",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(DataError::Invalid(format!(
                "median reference value {i} is {} (must be finite and non-negative)",
                values[i]
            )));
        }
        Ok(Self { values })
    }

    /// The reference values, [`VALUES`] long, channel-major MERL order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The reference with its peak at the mirror direction flattened: at every theta_h below
    /// `theta_h_deg`, each value is capped by the value of the same (theta_d, phi_d, channel)
    /// at the first theta_h sample at or above it. The median over a collection of glossy
    /// materials peaks sharply at theta_h ~ 0; eq. (1) then divides a material with a weaker
    /// highlight by that peak, so its highlight is a dip in the mapped space whose errors come
    /// back multiplied by the peak (`d rho / d y = rho + rho_ref + eps`): a dark or tinted dot.
    /// Capped, a highlight above the cap maps logarithmically, as the rest of the table does.
    pub fn flattened_below(&self, theta_h_deg: f64) -> Self {
        let edge = (0..N_THETA_H)
            .find(|&h| crate::merl::grid::theta_h_of(h).to_degrees() >= theta_h_deg)
            .unwrap_or(N_THETA_H);
        let mut values = self.values.clone();
        if edge == 0 || edge == N_THETA_H {
            return Self { values };
        }
        let per_h = N_THETA_D * N_PHI_D;
        for channel in values.chunks_exact_mut(CELLS) {
            let (below, rest) = channel.split_at_mut(edge * per_h);
            let cap = &rest[..per_h];
            for row in below.chunks_exact_mut(per_h) {
                for (v, c) in row.iter_mut().zip(cap) {
                    *v = v.min(*c);
                }
            }
        }
        Self { values }
    }

    /// Eq. (1) applied to every value of `table`: [`VALUES`] mapped values, channel-major MERL
    /// order. Values of invalid cells map to 0.0 (the paper sets invalid entries to zero, §3.2).
    pub fn map(&self, table: &MerlTable) -> Vec<f32> {
        let mut out = vec![0f32; VALUES];
        let rho = table.values();
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(b, chunk)| {
            let start = b * CHUNK;
            for (k, o) in chunk.iter_mut().enumerate() {
                let i = start + k;
                if table.is_valid(i % CELLS) {
                    *o = log_relative(f64::from(rho[i]), f64::from(self.values[i])) as f32;
                }
            }
        });
        out
    }

    /// The inverse of [`Self::map`]: reflectance from `mapped` values ([`VALUES`], channel-major
    /// MERL order) on the cells where `mask` ([`CELLS`] entries, MERL order) is true. Results are
    /// clamped to >= 0 (a negative value would mark the cell invalid); cells outside the mask get
    /// [`INVALID_VALUE`]. Fails on wrong lengths, a non-finite mapped value in a valid cell, or a
    /// mapped value so large that the reflectance overflows f32.
    pub fn unmap(&self, mapped: &[f32], mask: &[bool]) -> Result<MerlTable> {
        if mapped.len() != VALUES {
            return Err(DataError::Invalid(format!(
                "unmap needs {VALUES} mapped values, got {}",
                mapped.len()
            )));
        }
        if mask.len() != CELLS {
            return Err(DataError::Invalid(format!(
                "unmap needs a mask of {CELLS} cells, got {}",
                mask.len()
            )));
        }
        let mut out = vec![INVALID_VALUE; VALUES];
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(b, chunk)| {
            let start = b * CHUNK;
            for (k, o) in chunk.iter_mut().enumerate() {
                let i = start + k;
                if mask[i % CELLS] {
                    let rho = inverse_log_relative(f64::from(mapped[i]), f64::from(self.values[i]));
                    // NaN stays NaN (max would hide it) and is reported below.
                    *o = if rho < 0.0 { 0.0 } else { rho as f32 };
                }
            }
        });
        if let Some(i) = out.iter().position(|v| !v.is_finite()) {
            return Err(DataError::Invalid(format!(
                "mapped value {i} ({}) has no finite f32 reflectance",
                mapped[i]
            )));
        }
        MerlTable::from_values(out)
    }
}

/// Median of `values` (reordered in place); the mean of the two middle values for an even count;
/// 0 for none.
pub fn median(values: &mut [f32]) -> f32 {
    let n = values.len();
    if n == 0 {
        return 0.0;
    }
    values.sort_unstable_by(f32::total_cmp);
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (0.5 * (f64::from(values[n / 2 - 1]) + f64::from(values[n / 2]))) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::grid::cell_is_valid;
    use crate::merl::{cell_coords, cell_index};

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    /// A table whose valid values are `f(channel, cell)`; invalid cells as in the MERL grid.
    fn table_with(f: impl Fn(usize, usize) -> f32) -> MerlTable {
        let mut values = vec![INVALID_VALUE; VALUES];
        for cell in 0..CELLS {
            let (h, d, p) = cell_coords(cell);
            if cell_is_valid(h, d, p) {
                for c in 0..3 {
                    values[c * CELLS + cell] = f(c, cell);
                }
            }
        }
        MerlTable::from_values(values).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn median_of_known_sets() {
        assert_eq!(median(&mut []), 0.0);
        assert_eq!(median(&mut [3.0]), 3.0);
        assert_eq!(median(&mut [5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [7.0, 7.0, 1.0, 100.0, 0.0]), 7.0);
    }

    #[test]
    fn reference_is_the_per_value_median_of_valid_values() -> TestResult {
        // Four tables with values 1, 2, 3, 10 (times a per-value pattern); in the fourth one,
        // one cell is invalid so its median is over three values.
        let special = cell_index(10, 20, 90);
        let tables: Vec<MerlTable> = [1.0f32, 2.0, 3.0, 10.0]
            .iter()
            .enumerate()
            .map(|(t, s)| {
                let mut table = table_with(|c, cell| s * (1.0 + c as f32 + (cell % 7) as f32));
                if t == 3 {
                    for c in 0..3 {
                        table.values_mut()[c * CELLS + special] = INVALID_VALUE;
                    }
                }
                table
            })
            .collect();
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let reference = MedianReference::from_tables(&refs)?;
        let v = reference.values();
        let cell = cell_index(5, 5, 5);
        for c in 0..3 {
            let pattern = 1.0 + c as f32 + (cell % 7) as f32;
            // Even count: mean of 2 and 3 times the pattern.
            assert_eq!(v[c * CELLS + cell], 2.5 * pattern);
            let pattern = 1.0 + c as f32 + (special % 7) as f32;
            // Odd count (10 excluded as invalid): 2 times the pattern.
            assert_eq!(v[c * CELLS + special], 2.0 * pattern);
        }
        // A cell invalid everywhere (theta_d near 90 degrees, phi_d = 0) gets reference 0.
        let invalid = cell_index(60, 89, 0);
        assert!(!cell_is_valid(60, 89, 0));
        assert_eq!(v[invalid], 0.0);
        assert!(MedianReference::from_tables(&[]).is_err());

        // Less a constant per table and channel: the median of the remainders, floored at 0.
        let less = [[0.5, 0.0, 100.0], [1.0, 0.0, 100.0], [1.5, 0.0, 100.0], [0.0, 0.0, 100.0]];
        let remainders = MedianReference::from_remainders(&refs, &less)?;
        let pattern = |c: usize| 1.0 + c as f32 + (cell % 7) as f32;
        let p = pattern(0);
        let mut sorted = [1.0 * p - 0.5, 2.0 * p - 1.0, 3.0 * p - 1.5, 10.0 * p];
        sorted.sort_by(f32::total_cmp);
        let expected = (0.5 * (f64::from(sorted[1]) + f64::from(sorted[2]))) as f32;
        assert_eq!(remainders.values()[cell], expected);
        assert_eq!(remainders.values()[CELLS + cell], v[CELLS + cell]);
        assert_eq!(remainders.values()[2 * CELLS + cell], 0.0, "floored at 0");
        assert!(MedianReference::from_remainders(&refs, &less[..2]).is_err());
        Ok(())
    }

    #[test]
    fn map_is_eq1_and_unmap_is_its_exact_inverse() -> TestResult {
        // Values spanning the HDR range of measured BRDFs, 1e-5 .. 1e4 (1/sr).
        let table = table_with(|c, cell| {
            let t = ((cell * 7919 + c * 104729) % 100_003) as f32 / 100_003.0;
            10f32.powf(-5.0 + 9.0 * t)
        });
        let reference = MedianReference::from_values(
            (0..VALUES).map(|i| ((i * 31) % 1000) as f32 / 100.0).collect(),
        )?;
        let mapped = reference.map(&table);
        let mask = table.mask();
        // Eq. (1) checked on a few values against the formula written out.
        for i in [0usize, 12345, CELLS + 777_777, 2 * CELLS + 1_000_000] {
            let cell = i % CELLS;
            if mask[cell] {
                let (rho, r) = (table.values()[i] as f64, reference.values()[i] as f64);
                let expect = ((rho + 0.001) / (r + 0.001) + 1.0).ln();
                assert!((mapped[i] as f64 - expect).abs() <= 1e-6 * expect, "{i}");
            } else {
                assert_eq!(mapped[i], 0.0);
            }
        }
        let back = reference.unmap(&mapped, &mask)?;
        assert_eq!(back.mask(), mask);
        for i in 0..VALUES {
            if !mask[i % CELLS] {
                assert_eq!(back.values()[i], INVALID_VALUE);
                continue;
            }
            let (rho, r, y) =
                (table.values()[i] as f64, reference.values()[i] as f64, mapped[i] as f64);
            let got = back.values()[i] as f64;
            // The only error is the f32 rounding of the mapped value y (relative 2^-24) and of
            // the result: d rho = (rho_ref + eps) e^y dy = (rho + rho_ref + 2 eps) dy.
            let tol = f64::from(f32::EPSILON) * ((rho + r + 2.0 * EPSILON) * y.max(1.0) + rho);
            assert!((got - rho).abs() <= tol, "value {i}: {got} vs {rho} (tol {tol})");
        }
        Ok(())
    }

    #[test]
    fn unmap_clamps_to_zero_and_rejects_bad_input() -> TestResult {
        let reference = MedianReference::from_values(vec![0.5; VALUES])?;
        let mask = vec![true; CELLS];
        let table = reference.unmap(&vec![-3.0; VALUES], &mask)?;
        assert!(table.values().iter().all(|v| *v == 0.0));
        assert!(reference.unmap(&vec![0.0; VALUES - 1], &mask).is_err());
        assert!(reference.unmap(&vec![0.0; VALUES], &mask[1..]).is_err());
        let mut bad = vec![0.0; VALUES];
        bad[17] = f32::NAN;
        assert!(reference.unmap(&bad, &mask).is_err());
        bad[17] = 200.0; // e^200 overflows f32
        assert!(reference.unmap(&bad, &mask).is_err());
        let mut masked = mask.clone();
        masked[17] = false;
        assert_eq!(reference.unmap(&bad, &masked)?.values()[17], INVALID_VALUE);
        Ok(())
    }

    #[test]
    fn from_values_rejects_bad_values() {
        assert!(MedianReference::from_values(vec![0.0; 10]).is_err());
        let mut v = vec![0.0; VALUES];
        v[3] = -1.0;
        assert!(MedianReference::from_values(v.clone()).is_err());
        v[3] = f32::INFINITY;
        assert!(MedianReference::from_values(v).is_err());
    }

    #[test]
    fn a_flattened_reference_caps_the_peak_below_the_angle_and_keeps_the_rest() {
        use crate::merl::grid::{cell_index, theta_h_of};
        // A reference peaked at theta_h = 0, falling with theta_h, and different per colour
        // and phi_d.
        let values: Vec<f32> = (0..VALUES)
            .map(|i| {
                let (c, cell) = (i / CELLS, i % CELLS);
                let (h, dp) = (cell / (N_THETA_D * N_PHI_D), cell % (N_THETA_D * N_PHI_D));
                (c + 1) as f32 * (1.0 + (dp % 7) as f32) * (10.0 / (1.0 + h as f32))
            })
            .collect();
        let reference = MedianReference::from_values(values).unwrap();
        let flat = reference.flattened_below(10.0);
        let edge = (0..N_THETA_H).find(|&h| theta_h_of(h).to_degrees() >= 10.0).unwrap();
        assert!(edge > 20 && edge < 40, "{edge}");
        for c in 0..3 {
            for (d, p) in [(0, 0), (17, 33), (89, 179)] {
                let at =
                    |r: &MedianReference, h: usize| r.values()[c * CELLS + cell_index(h, d, p)];
                for h in 0..edge {
                    assert_eq!(at(&flat, h), at(&reference, edge), "h {h}");
                }
                for h in edge..N_THETA_H {
                    assert_eq!(at(&flat, h), at(&reference, h));
                }
            }
        }
        // Below the angle a value under the cap stays; no angle or 0 deg changes nothing.
        let mut dip = reference.values().to_vec();
        dip[cell_index(0, 5, 5)] = 0.0;
        let dip = MedianReference::from_values(dip).unwrap().flattened_below(10.0);
        assert_eq!(dip.values()[cell_index(0, 5, 5)], 0.0);
        assert_eq!(reference.flattened_below(0.0), reference);
        assert_eq!(reference.flattened_below(95.0), reference);
    }
}

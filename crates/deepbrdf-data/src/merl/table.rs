//! The in-memory MERL table: 3 colour channels over the 90 x 90 x 180 grid of
//! Rusinkiewicz half/difference angles (theta_h, theta_d, phi_d), Matusik et al. 2003.
//!
//! Values are reflectance in physical units (1/sr, f32): the file's stored value multiplied by
//! the channel's colour scale ([`MERL_SCALE`]). Cells where the incoming or outgoing direction is
//! below the horizon are invalid; they hold a negative value, as in MERL's own files.

use super::grid::{cell_coords, cell_index, cell_is_valid, CELLS, ROW, VALUES};
use crate::error::{DataError, Result};

/// Colour scales of MERL's reference reader (`BRDFRead.cpp`, Matusik et al. 2003): the stored value
/// of channel c times `MERL_SCALE[c]` is reflectance in 1/sr. Red 1/1500, green 1.15/1500,
/// blue 1.66/1500.
pub const MERL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// Value stored in invalid (below-horizon) cells of tables this crate writes, in physical units.
/// Any negative value marks a cell invalid when reading.
pub const INVALID_VALUE: f32 = -1.0;

/// A full MERL BRDF in physical units: channel-major, each channel in MERL's file order.
#[derive(Clone, PartialEq)]
pub struct MerlTable {
    values: Vec<f32>,
}

impl std::fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "MerlTable {{ {} values, {} valid cells }}",
            self.values.len(),
            self.valid_cells()
        )
    }
}

impl MerlTable {
    /// Wraps `values` (length [`VALUES`], channel-major, MERL order, physical units).
    /// Rejects the wrong length and NaN or infinite values.
    pub fn from_values(values: Vec<f32>) -> Result<Self> {
        if values.len() != VALUES {
            return Err(DataError::Invalid(format!(
                "a MERL table has {VALUES} values, got {}",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(DataError::Invalid(format!("value {i} is {} (not finite)", values[i])));
        }
        Ok(Self { values })
    }

    /// A table filled one theta_h row at a time, rows in parallel (rayon): `fill(i, [r, g, b])`
    /// writes row `i` of the three channels ([`ROW`] cells each, preset to [`INVALID_VALUE`]).
    /// Rows are independent, so the table does not depend on the thread count. Fails if a value
    /// is non-finite (see [`MerlTable::from_values`]).
    pub fn from_par_rows(fill: impl Fn(usize, [&mut [f32]; 3]) + Sync) -> Result<Self> {
        use rayon::prelude::*;
        let mut values = vec![INVALID_VALUE; VALUES];
        let (r, rest) = values.split_at_mut(CELLS);
        let (g, b) = rest.split_at_mut(CELLS);
        r.par_chunks_mut(ROW)
            .zip(g.par_chunks_mut(ROW))
            .zip(b.par_chunks_mut(ROW))
            .enumerate()
            .for_each(|(i, ((r, g), b))| fill(i, [r, g, b]));
        Self::from_values(values)
    }

    /// Builds a table by evaluating `f(theta_h, theta_d, phi_d) -> rgb` (indices) at valid cells;
    /// invalid cells get [`INVALID_VALUE`].
    pub fn from_fn(mut f: impl FnMut(usize, usize, usize) -> [f32; 3]) -> Self {
        let mut values = vec![INVALID_VALUE; VALUES];
        for cell in 0..CELLS {
            let (h, d, p) = cell_coords(cell);
            if cell_is_valid(h, d, p) {
                let rgb = f(h, d, p);
                for c in 0..3 {
                    values[c * CELLS + cell] = rgb[c];
                }
            }
        }
        Self { values }
    }

    /// All values, channel-major.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Mutable access to all values, channel-major.
    pub fn values_mut(&mut self) -> &mut [f32] {
        &mut self.values
    }

    /// Consumes the table, returning its values.
    pub fn into_values(self) -> Vec<f32> {
        self.values
    }

    /// One channel's values (0 = red, 1 = green, 2 = blue).
    pub fn channel(&self, c: usize) -> &[f32] {
        &self.values[c * CELLS..(c + 1) * CELLS]
    }

    /// RGB reflectance (1/sr) of a cell given by its indices.
    #[inline]
    pub fn rgb(&self, theta_h: usize, theta_d: usize, phi_d: usize) -> [f32; 3] {
        let i = cell_index(theta_h, theta_d, phi_d);
        [self.values[i], self.values[CELLS + i], self.values[2 * CELLS + i]]
    }

    /// Whether a cell (flat index within a channel) holds a measurement: all channels
    /// non-negative, the MERL convention.
    #[inline]
    pub fn is_valid(&self, cell: usize) -> bool {
        self.values[cell] >= 0.0
            && self.values[CELLS + cell] >= 0.0
            && self.values[2 * CELLS + cell] >= 0.0
    }

    /// The validity mask, one entry per cell in MERL order.
    pub fn mask(&self) -> Vec<bool> {
        (0..CELLS).map(|c| self.is_valid(c)).collect()
    }

    /// Number of valid cells.
    pub fn valid_cells(&self) -> usize {
        (0..CELLS).filter(|&c| self.is_valid(c)).count()
    }
}

//! The network layout of §3.2 (Hu et al. 2020): a BRDF "represented by reordered Rusinkiewicz
//! half-difference angle coordinates (phi_d, theta_h, theta_d) and reshaped into 540 x 90 x 90",
//! i.e. a stack of 180 phi_d slices, each an RGB image with rows theta_h and columns theta_d.
//!
//! Index of a value in the layout (row-major, `[channel][row][column]`):
//! `((phi_d * 3 + rgb) * 90 + theta_h) * 90 + theta_d`, so channel = phi_d * 3 + rgb.
//! MERL order (the input of [`to_layout`]) is channel-major with
//! `cell = (theta_h * 90 + theta_d) * 180 + phi_d` ([`cell_index`]).

use crate::merl::{cell_index, CELLS, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
use rayon::prelude::*;

/// Channels of the layout: 180 phi_d slices x 3 colours.
pub const SLICE_CHANNELS: usize = 3 * N_PHI_D;
/// Side of each slice image: 90 (theta_h rows = theta_d columns = 90).
pub const SIDE: usize = N_THETA_H;
/// Values per layout channel: 90 x 90.
pub const PLANE: usize = SIDE * SIDE;
/// Values per phi_d slice (its 3 colour channels).
pub const SLICE_VALUES: usize = 3 * PLANE;
/// Values of the whole layout, 540 x 90 x 90 = [`VALUES`] (the autoencoder's input size).
pub const LAYOUT_VALUES: usize = SLICE_CHANNELS * PLANE;

const _: () = assert!(N_THETA_H == N_THETA_D && LAYOUT_VALUES == VALUES);

/// Index in the layout of colour `rgb` at cell (theta_h, theta_d, phi_d).
#[inline]
pub fn layout_index(theta_h: usize, theta_d: usize, phi_d: usize, rgb: usize) -> usize {
    ((phi_d * 3 + rgb) * SIDE + theta_h) * SIDE + theta_d
}

/// Reorders [`VALUES`] values from MERL order (channel-major) into the 540 x 90 x 90 layout.
///
/// # Panics
/// If `values` is not [`VALUES`] long.
pub fn to_layout(values: &[f32]) -> Vec<f32> {
    assert_eq!(values.len(), VALUES, "to_layout needs {VALUES} values in MERL order");
    let mut out = vec![0f32; VALUES];
    out.par_chunks_mut(PLANE).enumerate().for_each(|(channel, plane)| {
        let (phi_d, rgb) = (channel / 3, channel % 3);
        let src = &values[rgb * CELLS..(rgb + 1) * CELLS];
        for (row, line) in plane.chunks_exact_mut(SIDE).enumerate() {
            for (col, v) in line.iter_mut().enumerate() {
                *v = src[cell_index(row, col, phi_d)];
            }
        }
    });
    out
}

/// Reorders a 540 x 90 x 90 layout back into [`VALUES`] values in MERL order; the inverse of
/// [`to_layout`].
///
/// # Panics
/// If `layout` is not [`VALUES`] long.
pub fn from_layout(layout: &[f32]) -> Vec<f32> {
    assert_eq!(layout.len(), VALUES, "from_layout needs a 540 x 90 x 90 layout");
    let mut out = vec![0f32; VALUES];
    // One work item per (colour, theta_h): 90 x 180 contiguous values in MERL order.
    out.par_chunks_mut(N_THETA_D * N_PHI_D).enumerate().for_each(|(item, block)| {
        let (rgb, theta_h) = (item / N_THETA_H, item % N_THETA_H);
        for (theta_d, line) in block.chunks_exact_mut(N_PHI_D).enumerate() {
            for (phi_d, v) in line.iter_mut().enumerate() {
                *v = layout[layout_index(theta_h, theta_d, phi_d, rgb)];
            }
        }
    });
    out
}

/// The validity mask ([`CELLS`] entries, MERL order, e.g. [`crate::MerlTable::mask`]) in the
/// layout: 1.0 where valid, 0.0 where invalid, the same for the 3 colours of a cell.
///
/// # Panics
/// If `mask` is not [`CELLS`] long.
pub fn mask_layout(mask: &[bool]) -> Vec<f32> {
    assert_eq!(mask.len(), CELLS, "mask_layout needs {CELLS} cells in MERL order");
    let mut out = vec![0f32; VALUES];
    out.par_chunks_mut(PLANE).enumerate().for_each(|(channel, plane)| {
        let phi_d = channel / 3;
        for (row, line) in plane.chunks_exact_mut(SIDE).enumerate() {
            for (col, v) in line.iter_mut().enumerate() {
                *v = if mask[cell_index(row, col, phi_d)] { 1.0 } else { 0.0 };
            }
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::grid::cell_is_valid;
    use crate::merl::{cell_coords, MerlTable};

    /// A distinct value for every (channel, cell): the flat MERL index itself.
    fn numbered() -> Vec<f32> {
        (0..VALUES).map(|i| i as f32).collect()
    }

    #[test]
    fn known_positions() {
        let layout = to_layout(&numbered());
        // Cell (theta_h 0, theta_d 0, phi_d 0), red: first value of both orders.
        assert_eq!(layout[0], 0.0);
        // Green of (0, 0, 0) is channel 1 of the layout.
        assert_eq!(layout[PLANE], CELLS as f32);
        // Red of phi_d = 1 at (0, 0) is channel 3; in MERL order it is index 1.
        assert_eq!(layout[3 * PLANE], 1.0);
        // Blue of (theta_h 7, theta_d 11, phi_d 100): channel 302, row 7, column 11.
        let merl = 2 * CELLS + cell_index(7, 11, 100);
        assert_eq!(layout[302 * PLANE + 7 * SIDE + 11], merl as f32);
        // The last value is blue of the last cell in both orders.
        assert_eq!(layout[VALUES - 1], (VALUES - 1) as f32);
    }

    #[test]
    fn round_trip_is_identity() {
        let values = numbered();
        let layout = to_layout(&values);
        assert_ne!(layout, values);
        assert_eq!(from_layout(&layout), values);
        // And the other way round.
        assert_eq!(to_layout(&from_layout(&values)), values);
    }

    #[test]
    fn mask_matches_values_layout() {
        let table = MerlTable::from_fn(|h, d, p| [h as f32, d as f32, p as f32]);
        let mask = table.mask();
        let mask_l = mask_layout(&mask);
        let values_l = to_layout(table.values());
        for (m, v) in mask_l.iter().zip(&values_l) {
            assert_eq!(*m == 1.0, *v >= 0.0);
            assert!(*m == 0.0 || *m == 1.0);
        }
        // Spot check against the grid definition.
        for cell in [0usize, 1000, 777_777, CELLS - 1] {
            let (h, d, p) = cell_coords(cell);
            let expect = if cell_is_valid(h, d, p) { 1.0 } else { 0.0 };
            for rgb in 0..3 {
                assert_eq!(mask_l[layout_index(h, d, p, rgb)], expect);
            }
        }
    }
}

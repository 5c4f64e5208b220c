//! The MERL sampling grid: its size and cell order, the angles at which each cell is sampled,
//! which cells lie above the horizon and the cosine weight of each cell (the one home of these
//! facts). MERL's reference reader `BRDFRead.cpp` bins a direction pair into cell
//! `floor(sqrt(theta_h / 90deg) * 90)`, `floor(theta_d / 90deg * 90)`, `floor(phi_d / 180deg *
//! 180)`, so a stored value stands for its bin: cells are sampled at their bin centres,
//! theta_h = ((i + 1/2) / 90)^2 * pi/2 (the centre in MERL's square-root warp),
//! theta_d = (j + 1/2) / 90 * pi/2, phi_d = (k + 1/2) / 180 * pi. (The NBRDF tabulation, and
//! this project before, used the lower edges, which shifts every value by half a cell for every
//! other MERL reader.)

use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

/// Number of theta_h samples (square-root warped over [0, pi/2)).
pub const N_THETA_H: usize = 90;
/// Number of theta_d samples (uniform over [0, pi/2)).
pub const N_THETA_D: usize = 90;
/// Number of phi_d samples (uniform over [0, pi); reciprocity folds [pi, 2pi) onto it).
pub const N_PHI_D: usize = 180;
/// Cells per colour channel: 1,458,000.
pub const CELLS: usize = N_THETA_H * N_THETA_D * N_PHI_D;
/// Values per table, all three channels: 4,374,000.
pub const VALUES: usize = 3 * CELLS;
/// Cells in one theta_h row of the grid (all theta_d and phi_d): 16,200.
pub const ROW: usize = N_THETA_D * N_PHI_D;

/// Flat index of a cell within one channel, in MERL's file order
/// (`phi_d + theta_d * 180 + theta_h * 180 * 90`).
#[inline]
pub fn cell_index(theta_h: usize, theta_d: usize, phi_d: usize) -> usize {
    (theta_h * N_THETA_D + theta_d) * N_PHI_D + phi_d
}

/// Inverse of [`cell_index`]: `(theta_h, theta_d, phi_d)` indices of a flat cell index.
#[inline]
pub fn cell_coords(cell: usize) -> (usize, usize, usize) {
    (cell / (N_THETA_D * N_PHI_D), (cell / N_PHI_D) % N_THETA_D, cell % N_PHI_D)
}

/// theta_h (radians) of index `i`: the bin centre in MERL's square-root warp.
#[inline]
pub fn theta_h_of(i: usize) -> f64 {
    let u = (i as f64 + 0.5) / N_THETA_H as f64;
    u * u * FRAC_PI_2
}

/// theta_d (radians) of index `j`: its bin centre.
#[inline]
pub fn theta_d_of(j: usize) -> f64 {
    (j as f64 + 0.5) / N_THETA_D as f64 * FRAC_PI_2
}

/// phi_d (radians) of index `k`, in (0, pi): its bin centre.
#[inline]
pub fn phi_d_of(k: usize) -> f64 {
    (k as f64 + 0.5) / N_PHI_D as f64 * PI
}

/// Whether both directions of a cell lie strictly above the horizon.
///
/// With the half vector at (theta_h, phi_h = 0) and the difference vector at (theta_d, phi_d),
/// Rusinkiewicz 2001 gives `cos theta_{i,o} = cos td cos th -/+ sin td cos pd sin th`;
/// the cell is valid when the smaller of the two is positive.
#[inline]
pub fn angles_are_valid(theta_h: f64, theta_d: f64, phi_d: f64) -> bool {
    let a = theta_d.cos() * theta_h.cos();
    let b = theta_d.sin() * phi_d.cos().abs() * theta_h.sin();
    a - b > 0.0
}

/// Whether the cell with indices (i, j, k) lies above the horizon at its sample angles (its bin
/// centre).
#[inline]
pub fn cell_is_valid(i: usize, j: usize, k: usize) -> bool {
    angles_are_valid(theta_h_of(i), theta_d_of(j), phi_d_of(k))
}

/// [`cell_is_valid`] of every cell in MERL order, evaluated once per process: the grid's
/// validity mask (the one home of this fact; tabulation, the baselines' domain and the codec use
/// it).
pub fn valid_mask() -> &'static [bool] {
    static MASK: OnceLock<Vec<bool>> = OnceLock::new();
    MASK.get_or_init(|| {
        (0..CELLS)
            .into_par_iter()
            .map(|c| {
                let (h, d, p) = cell_coords(c);
                cell_is_valid(h, d, p)
            })
            .collect()
    })
}

/// `cos(theta_i) cos(theta_o)` at a cell's sample angles. With the half vector at
/// (theta_h, phi_h = 0) and the difference vector at (theta_d, phi_d), Rusinkiewicz 2001 gives
/// `cos theta_{i,o} = cos td cos th -/+ sin td cos pd sin th` (the same expression as
/// [`angles_are_valid`]), so the product is `(cos td cos th)^2 - (sin td cos pd sin th)^2`; it is
/// positive exactly on valid cells. IPCA's log-relative mapping (Nielsen et al. 2015, §4) and the
/// cosine-weighted measures weight each cell by it.
pub fn cos_product(cell: usize) -> f64 {
    let (i, j, k) = cell_coords(cell);
    let (th, td, pd) = (theta_h_of(i), theta_d_of(j), phi_d_of(k));
    let a = td.cos() * th.cos();
    let b = td.sin() * pd.cos() * th.sin();
    (a - b) * (a + b)
}

/// [`cos_product`] of every cell (MERL order, [`CELLS`] long, negative on invalid cells) as f32,
/// computed once per process (each cell independently, so the result does not depend on the
/// thread count) and shared: mappings, measures and tests read it instead of re-evaluating the
/// trigonometry per cell.
pub fn cos_weights() -> &'static [f32] {
    static WEIGHTS: OnceLock<Vec<f32>> = OnceLock::new();
    WEIGHTS.get_or_init(|| (0..CELLS).into_par_iter().map(|c| cos_product(c) as f32).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cos_product_matches_the_grid_validity_and_known_angles() {
        // The first cell (bin centres at theta_h, theta_d under half a degree): both directions
        // within a degree of the normal.
        assert!((cos_product(cell_index(0, 0, 0)) - 1.0).abs() < 2e-4);
        // At each cell's sample angles, the product of the two directions' cosines.
        for (i, j, k) in [(0, 30, 17), (10, 45, 90), (40, 20, 3), (70, 10, 170)] {
            let a = crate::merl::coords::HalfDiff {
                theta_h: theta_h_of(i),
                phi_h: 0.0,
                theta_d: theta_d_of(j),
                phi_d: phi_d_of(k),
            };
            let (wi, wo) = a.to_dirs();
            assert!(
                (cos_product(cell_index(i, j, k)) - wi[2] * wo[2]).abs() < 1e-12,
                "{i} {j} {k}"
            );
        }
        for cell in (0..CELLS).step_by(97) {
            let (i, j, k) = cell_coords(cell);
            assert_eq!(cos_product(cell) > 0.0, cell_is_valid(i, j, k), "cell {cell}");
            assert_eq!(cos_weights()[cell], cos_product(cell) as f32);
        }
    }
}

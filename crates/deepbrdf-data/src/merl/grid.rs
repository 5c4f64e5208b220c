//! The MERL sampling grid: the angles at which each cell is sampled, and which cells lie above
//! the horizon. MERL's reference reader `BRDFRead.cpp` bins a direction pair into cell
//! `floor(sqrt(theta_h / 90deg) * 90)`, `floor(theta_d / 90deg * 90)`, `floor(phi_d / 180deg *
//! 180)`, so a stored value stands for its bin: cells are sampled at their bin centres,
//! theta_h = ((i + 1/2) / 90)^2 * pi/2 (the centre in MERL's square-root warp),
//! theta_d = (j + 1/2) / 90 * pi/2, phi_d = (k + 1/2) / 180 * pi. (The NBRDF tabulation, and
//! this project before, used the lower edges, which shifts every value by half a cell for every
//! other MERL reader.)

use super::table::{cell_coords, CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

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

//! IPCA, the "improved PCA" of the paper's §4: PCA after the log-relative mapping of
//! J. B. Nielsen, H. W. Jensen, R. Ramamoorthi, "On Optimal, Minimal BRDF Sampling for
//! Reflectance Acquisition", ACM TOG 34(6) (SIGGRAPH Asia) 2015, §4 (not incremental PCA):
//!
//! `rho' = ln((rho cos(theta_i) cos(theta_o) + eps) / (rho_ref cos(theta_i) cos(theta_o) + eps))`
//!
//! with `eps` = [`EPSILON`] = 0.001 and `rho_ref` the per-cell (and per-channel) median of the
//! training BRDFs. The cosine weighting de-emphasises grazing cells, whose values are the least
//! reliable and matter least in renderings. Rows are then mean-centred and truncated to k
//! components exactly as in [`crate::pca`].

use crate::baseline::{BaselineMethod, MappingKind};
use deepbrdf_data::merl::{cell_coords, grid, CELLS};
use rayon::prelude::*;
use std::sync::OnceLock;

/// eps of the log-relative mapping (Nielsen et al. 2015; the same 0.001 as the paper's eq. 1).
pub const EPSILON: f64 = 1e-3;

/// The forward mapping `ln((rho w + eps) / (rho_ref w + eps))`, `w = cos(theta_i) cos(theta_o)`.
#[inline]
pub fn log_relative(rho: f64, rho_ref: f64, w: f64) -> f64 {
    ((rho * w + EPSILON) / (rho_ref * w + EPSILON)).ln()
}

/// Inverse of [`log_relative`]: `rho = ((rho_ref w + eps) exp(y) - eps) / w`.
#[inline]
pub fn log_relative_inverse(y: f64, rho_ref: f64, w: f64) -> f64 {
    ((rho_ref * w + EPSILON) * y.exp() - EPSILON) / w
}

/// `cos(theta_i) cos(theta_o)` at a cell's sample angles ([`grid`]). With the half vector at
/// (theta_h, phi_h = 0) and the difference vector at (theta_d, phi_d), Rusinkiewicz 2001 gives
/// `cos theta_{i,o} = cos td cos th -/+ sin td cos pd sin th` (the same expression as
/// [`grid::angles_are_valid`]), so the product is `(cos td cos th)^2 - (sin td cos pd sin th)^2`;
/// it is positive exactly on valid cells.
pub fn cos_product(cell: usize) -> f64 {
    let (i, j, k) = cell_coords(cell);
    let (th, td, pd) = (grid::theta_h_of(i), grid::theta_d_of(j), grid::phi_d_of(k));
    let a = td.cos() * th.cos();
    let b = td.sin() * pd.cos() * th.sin();
    (a - b) * (a + b)
}

/// [`cos_product`] of every cell (MERL order, [`CELLS`] long, negative on invalid cells) as f32,
/// computed once per process (in parallel) and shared: mappings, measures and tests read it
/// instead of re-evaluating the trigonometry per cell.
pub fn cos_weights() -> &'static [f32] {
    static WEIGHTS: OnceLock<Vec<f32>> = OnceLock::new();
    WEIGHTS.get_or_init(|| (0..CELLS).into_par_iter().map(|c| cos_product(c) as f32).collect())
}

/// IPCA as a harness method.
#[derive(Clone, Copy, Debug, Default)]
pub struct Ipca;

impl Ipca {
    /// The method, as run by the harness.
    pub fn method() -> BaselineMethod {
        BaselineMethod::new("IPCA", MappingKind::LogRelative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::cell_index;

    #[test]
    fn mapping_round_trips() {
        for &rho in &[0.0, 1e-6, 0.01, 0.3, 2.0, 75.0, 4000.0] {
            for &rho_ref in &[0.0, 0.02, 1.0, 100.0] {
                for &w in &[1e-4, 0.05, 0.5, 1.0] {
                    let y = log_relative(rho, rho_ref, w);
                    let back = log_relative_inverse(y, rho_ref, w);
                    assert!(
                        (back - rho).abs() <= 1e-9 * (1.0 + rho),
                        "{rho} {rho_ref} {w}: {back}"
                    );
                }
            }
        }
        // Equal to the reference maps to 0, as in Nielsen et al.'s definition.
        assert_eq!(log_relative(0.7, 0.7, 0.3), 0.0);
    }

    #[test]
    fn cos_product_matches_the_grid_validity_and_known_angles() {
        // The first cell (bin centres at theta_h, theta_d under half a degree): both directions
        // within a degree of the normal.
        assert!((cos_product(cell_index(0, 0, 0)) - 1.0).abs() < 2e-4);
        // At each cell's sample angles, the product of the two directions' cosines.
        for (i, j, k) in [(0, 30, 17), (10, 45, 90), (40, 20, 3), (70, 10, 170)] {
            let a = deepbrdf_data::merl::coords::HalfDiff {
                theta_h: grid::theta_h_of(i),
                phi_h: 0.0,
                theta_d: grid::theta_d_of(j),
                phi_d: grid::phi_d_of(k),
            };
            let (wi, wo) = a.to_dirs();
            assert!(
                (cos_product(cell_index(i, j, k)) - wi[2] * wo[2]).abs() < 1e-12,
                "{i} {j} {k}"
            );
        }
        for cell in (0..CELLS).step_by(97) {
            let (i, j, k) = cell_coords(cell);
            assert_eq!(cos_product(cell) > 0.0, grid::cell_is_valid(i, j, k), "cell {cell}");
            assert_eq!(cos_weights()[cell], cos_product(cell) as f32);
        }
    }
}

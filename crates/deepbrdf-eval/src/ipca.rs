//! IPCA, the "improved PCA" of the paper's §4: PCA after the log-relative mapping of
//! J. B. Nielsen, H. W. Jensen, R. Ramamoorthi, "On Optimal, Minimal BRDF Sampling for
//! Reflectance Acquisition", ACM TOG 34(6) (SIGGRAPH Asia) 2015, §4 (not incremental PCA):
//!
//! `rho' = ln((rho cos(theta_i) cos(theta_o) + eps) / (rho_ref cos(theta_i) cos(theta_o) + eps))`
//!
//! with `eps` = [`EPSILON`] = 0.001 and `rho_ref` the per-cell (and per-channel) median of the
//! training BRDFs. The cosine weighting de-emphasises grazing cells, whose values are the least
//! reliable and matter least in renderings. Rows are then mean-centred and truncated to k
//! components exactly as in [`crate::pca`] (the harness method is
//! `BaselineMethod::ipca`). The weights are the grid's
//! ([`deepbrdf_data::merl::grid::cos_weights`]).

/// eps of the log-relative mapping (Nielsen et al. 2015; the same 0.001 as the paper's eq. 1).
pub const EPSILON: f64 = 1e-3;

/// The forward mapping `ln((rho w + eps) / (rho_ref w + eps))`, `w = cos(theta_i) cos(theta_o)`.
/// A negative `rho` (a specular remainder where a diffuse part taken off exceeds the table,
/// [`crate::separation`]) is floored at `rho w = -eps / 2`, so the logarithm stays finite.
#[inline]
pub fn cosine_log_relative(rho: f64, rho_ref: f64, w: f64) -> f64 {
    cosine_log_relative_eps(rho, rho_ref, w, EPSILON)
}

/// Inverse of [`cosine_log_relative`]: `rho = ((rho_ref w + eps) exp(y) - eps) / w`.
#[inline]
pub fn cosine_log_relative_inverse(y: f64, rho_ref: f64, w: f64) -> f64 {
    cosine_log_relative_inverse_eps(y, rho_ref, w, EPSILON)
}

/// [`cosine_log_relative`] with another `eps` (a separated specular part, whose values near 0
/// [`crate::separation`] may want weighted less).
#[inline]
pub fn cosine_log_relative_eps(rho: f64, rho_ref: f64, w: f64, eps: f64) -> f64 {
    ((rho * w + eps).max(0.5 * eps) / (rho_ref * w + eps)).ln()
}

/// Inverse of [`cosine_log_relative_eps`].
#[inline]
pub fn cosine_log_relative_inverse_eps(y: f64, rho_ref: f64, w: f64, eps: f64) -> f64 {
    ((rho_ref * w + eps) * y.exp() - eps) / w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_round_trips() {
        for &rho in &[0.0, 1e-6, 0.01, 0.3, 2.0, 75.0, 4000.0] {
            for &rho_ref in &[0.0, 0.02, 1.0, 100.0] {
                for &w in &[1e-4, 0.05, 0.5, 1.0] {
                    let y = cosine_log_relative(rho, rho_ref, w);
                    let back = cosine_log_relative_inverse(y, rho_ref, w);
                    assert!(
                        (back - rho).abs() <= 1e-9 * (1.0 + rho),
                        "{rho} {rho_ref} {w}: {back}"
                    );
                }
            }
        }
        // Equal to the reference maps to 0, as in Nielsen et al.'s definition.
        assert_eq!(cosine_log_relative(0.7, 0.7, 0.3), 0.0);
    }
}

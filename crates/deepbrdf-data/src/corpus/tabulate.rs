//! Tabulation of an analytic BRDF on the MERL grid: each valid cell gets the BRDF's value at
//! the cell's sample angles ([`crate::merl::grid`], its bin centre) with phi_h = 0, as the NBRDF
//! tabulation does (an isotropic BRDF does not depend on phi_h). Rows of theta_h are filled in
//! parallel; each cell is computed on its own, so the table does not depend on the thread count.

use crate::error::{DataError, Result};
use crate::merl::coords::HalfDiff;
use crate::merl::grid::{phi_d_of, theta_d_of, theta_h_of, valid_mask, N_PHI_D, N_THETA_D, ROW};
use crate::merl::MerlTable;

/// Tabulates `brdf(wi, wo) -> rgb` (1/sr, unit directions, z = normal) on the MERL grid.
/// Invalid (below-horizon) cells get [`crate::merl::INVALID_VALUE`]. Fails if a value is not
/// finite in f32.
pub fn tabulate(brdf: impl Fn([f64; 3], [f64; 3]) -> [f64; 3] + Sync) -> Result<MerlTable> {
    let mask = valid_mask();
    MerlTable::from_par_rows(|h, [r, g, b]| {
        let theta_h = theta_h_of(h);
        for d in 0..N_THETA_D {
            let theta_d = theta_d_of(d);
            for p in 0..N_PHI_D {
                let k = d * N_PHI_D + p;
                if !mask[h * ROW + k] {
                    continue;
                }
                let angles = HalfDiff { theta_h, phi_h: 0.0, theta_d, phi_d: phi_d_of(p) };
                let (wi, wo) = angles.to_dirs();
                let rgb = brdf(wi, wo);
                (r[k], g[k], b[k]) = (rgb[0] as f32, rgb[1] as f32, rgb[2] as f32);
            }
        }
    })
    .map_err(|e| DataError::Invalid(format!("tabulating an analytic BRDF: {e}")))
}

impl super::material::Material {
    /// This material tabulated on the MERL grid ([`tabulate`]).
    pub fn table(&self) -> Result<MerlTable> {
        tabulate(|wi, wo| self.eval(wi, wo))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::grid::{cell_coords, CELLS};
    use crate::merl::INVALID_VALUE;

    #[test]
    fn cells_hold_the_brdf_at_their_sample_angles() {
        // A BRDF that encodes its arguments: cos theta_i, cos theta_o and wi . wo.
        let f = |wi: [f64; 3], wo: [f64; 3]| {
            [wi[2], wo[2], wi[0] * wo[0] + wi[1] * wo[1] + wi[2] * wo[2]]
        };
        let table = tabulate(f).expect("finite");
        let mask = valid_mask();
        for cell in (0..CELLS).step_by(7919) {
            let (h, d, p) = cell_coords(cell);
            let rgb = table.rgb(h, d, p);
            if !mask[cell] {
                assert_eq!(rgb, [INVALID_VALUE; 3]);
                continue;
            }
            let angles = HalfDiff {
                theta_h: theta_h_of(h),
                phi_h: 0.0,
                theta_d: theta_d_of(d),
                phi_d: phi_d_of(p),
            };
            let (wi, wo) = angles.to_dirs();
            assert_eq!(rgb, f(wi, wo).map(|v| v as f32), "cell {cell}");
        }
    }

    #[test]
    fn a_non_finite_value_is_an_error() {
        let err = tabulate(|wi, _| [1.0 / (wi[2] - wi[2]); 3]).expect_err("infinite");
        assert!(err.to_string().contains("not finite"), "{err}");
    }
}

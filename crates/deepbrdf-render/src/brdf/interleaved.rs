//! A render-side copy of a MERL table laid out for fast lookups. `MerlTable` stores the three
//! channels in separate blocks (MERL's file order), so one trilinear lookup touches 8 cells in
//! each of 3 blocks: up to 24 cache lines of a 17.5 MB table, the renderer's main cost. Here the
//! RGB values of a cell sit together (a cache line holds 5 cells), and angles come from a
//! polynomial `atan2` instead of libm's. Coordinates and index conventions are those of
//! `deepbrdf_data::merl::coords`, and the result equals `MerlTable::lookup_interpolated` to
//! about 1e-6 relative (tested below).

use deepbrdf_data::merl::coords::{
    continuous_phi_d, continuous_theta_d, continuous_theta_h, half_and_difference,
};
use deepbrdf_data::merl::{cell_index, MerlTable, CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// RGB per cell, interleaved; invalid cells hold a negative red value.
#[derive(Clone)]
pub struct InterleavedTable {
    rgb: Vec<[f32; 3]>,
}

impl std::fmt::Debug for InterleavedTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "InterleavedTable {{ {} cells }}", self.rgb.len())
    }
}

/// `atan(a)` for `a` in [0, 1]: reduced to `|t| <= tan(pi/8)` by `atan(a) = pi/4 + atan((a-1)/(a+1))`
/// when `a > tan(pi/8)`, then the odd Taylor series to `t^15` (truncation below
/// `tan(pi/8)^17 / 17 < 2e-8` rad).
#[inline]
fn atan_unit(a: f64) -> f64 {
    let (t, offset) =
        if a > 0.414_213_562_373_095_1 { ((a - 1.0) / (a + 1.0), FRAC_PI_4) } else { (a, 0.0) };
    let t2 = t * t;
    let series = 1.0
        + t2 * (-1.0 / 3.0
            + t2 * (1.0 / 5.0
                + t2 * (-1.0 / 7.0
                    + t2 * (1.0 / 9.0
                        + t2 * (-1.0 / 11.0 + t2 * (1.0 / 13.0 + t2 * (-1.0 / 15.0)))))));
    offset + t * series
}

/// `atan2(y, x)` in (-pi, pi] to within 2e-8 rad (0 for (0, 0), like libm).
#[inline]
pub fn atan2_fast(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = if ax < ay { (ax, ay) } else { (ay, ax) };
    if !(hi > 0.0) {
        return 0.0;
    }
    let mut r = atan_unit(lo / hi);
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// Lower index, upper index and upper weight of fractional index `u` on a clamped axis of `n`.
#[inline]
fn split_clamped(u: f64, n: usize) -> (usize, usize, f64) {
    let i0 = (u as usize).min(n - 1);
    if i0 + 1 >= n {
        (i0, i0, 0.0)
    } else {
        (i0, i0 + 1, u - i0 as f64)
    }
}

impl InterleavedTable {
    /// The interleaved copy of `table`.
    pub fn new(table: &MerlTable) -> Self {
        let v = table.values();
        let rgb = (0..CELLS)
            .map(|c| {
                let x = [v[c], v[CELLS + c], v[2 * CELLS + c]];
                if x.iter().all(|&e| e >= 0.0) {
                    x
                } else {
                    [-1.0; 3]
                }
            })
            .collect();
        Self { rgb }
    }

    /// Trilinear reflectance (1/sr) at (wi, wo), as `MerlTable::lookup_interpolated`: theta_h
    /// and theta_d clamped, phi_d circular, invalid neighbours skipped and the weights
    /// renormalised; 0 at or below the horizon or where no neighbour is valid.
    #[inline]
    pub fn lookup_interpolated(&self, wi: [f64; 3], wo: [f64; 3]) -> [f32; 3] {
        if !(wi[2] > 0.0 && wo[2] > 0.0) {
            return [0.0; 3];
        }
        let (h, d) = half_and_difference(wi, wo);
        let theta_h = atan2_fast((h[0] * h[0] + h[1] * h[1]).sqrt(), h[2]);
        let theta_d = atan2_fast((d[0] * d[0] + d[1] * d[1]).sqrt(), d[2]);
        let phi_d = atan2_fast(d[1], d[0]);
        let (h0, h1, th) = split_clamped(continuous_theta_h(theta_h), N_THETA_H);
        let (d0, d1, td) = split_clamped(continuous_theta_d(theta_d), N_THETA_D);
        let up = continuous_phi_d(phi_d);
        let p0 = (up as usize).min(N_PHI_D - 1);
        let tp = up - p0 as f64;
        let p1 = (p0 + 1) % N_PHI_D;
        let mut acc = [0f64; 3];
        let mut weight = 0f64;
        for (hi, wh) in [(h0, 1.0 - th), (h1, th)] {
            for (di, wd) in [(d0, 1.0 - td), (d1, td)] {
                let w_hd = wh * wd;
                for (pi, wp) in [(p0, 1.0 - tp), (p1, tp)] {
                    let w = w_hd * wp;
                    if w <= 0.0 {
                        continue;
                    }
                    let rgb = self.rgb[cell_index(hi, di, pi)];
                    if rgb[0] >= 0.0 {
                        for (a, x) in acc.iter_mut().zip(rgb) {
                            *a += w * f64::from(x);
                        }
                        weight += w;
                    }
                }
            }
        }
        if weight > 0.0 {
            acc.map(|a| (a / weight) as f32)
        } else {
            [0.0; 3]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::coords::direction;
    use deepbrdf_data::testing::synthetic_table;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn fast_atan2_matches_libm() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..100_000 {
            let (y, x): (f64, f64) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            assert!((atan2_fast(y, x) - y.atan2(x)).abs() < 2e-8, "{y} {x}");
        }
        for (y, x) in [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0), (1e-300, 1.0), (0.0, 0.0)]
        {
            assert!((atan2_fast(y, x) - f64::atan2(y, x)).abs() < 2e-8, "{y} {x}");
        }
    }

    #[test]
    fn equals_the_data_layer_lookup() {
        // A table with invalid cells (below the horizon) and structure in every coordinate.
        let table = synthetic_table(3);
        let fast = InterleavedTable::new(&table);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut dir = || {
            let z: f64 = rng.random_range(0.0..1.0);
            direction(z.acos(), rng.random_range(-PI..PI))
        };
        for _ in 0..50_000 {
            let (wi, wo) = (dir(), dir());
            let (a, b) = (fast.lookup_interpolated(wi, wo), table.lookup_interpolated(wi, wo));
            for c in 0..3 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-5 * b[c].abs() + 1e-6,
                    "{wi:?} {wo:?}: {a:?} vs {b:?}"
                );
            }
        }
        assert_eq!(fast.lookup_interpolated([0.0, 0.6, -0.8], [0.0, 0.0, 1.0]), [0.0; 3]);
    }
}

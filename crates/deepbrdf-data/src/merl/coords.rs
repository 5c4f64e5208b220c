//! Rusinkiewicz half/difference coordinates (S. Rusinkiewicz, "A New Change of Variables for
//! Efficient BRDF Representation", EGWR 1998; used by MERL, Matusik et al. 2003) and MERL's
//! index mapping (`BRDFRead.cpp`, MERL's reference reader).
//!
//! Directions are unit `[f64; 3]` vectors in the local frame of the surface, z = normal. The
//! half vector is `h = normalize(wi + wo)` with polar angles (theta_h, phi_h); the difference
//! vector `d` is `wi` expressed in the frame where `h` is the pole: `wi` rotated by -phi_h about
//! the normal, then by -theta_h about the binormal y, with polar angles (theta_d, phi_d). Swapping
//! wi and wo leaves theta_h, phi_h, theta_d unchanged and shifts phi_d by pi, which is why MERL
//! folds phi_d into [0, pi) (reciprocity).

use super::grid::{N_PHI_D, N_THETA_D, N_THETA_H};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A direction pair in Rusinkiewicz's half/difference angles (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfDiff {
    /// Polar angle of the half vector, [0, pi].
    pub theta_h: f64,
    /// Azimuth of the half vector, (-pi, pi].
    pub phi_h: f64,
    /// Polar angle of the difference vector, [0, pi].
    pub theta_d: f64,
    /// Azimuth of the difference vector, (-pi, pi].
    pub phi_d: f64,
}

impl HalfDiff {
    /// Half/difference angles of the pair (wi, wo) of unit vectors. If wi = -wo the half vector
    /// is undefined; the normal is used.
    #[inline]
    pub fn from_dirs(wi: [f64; 3], wo: [f64; 3]) -> Self {
        let (h, d) = half_and_difference(wi, wo);
        let sin_theta_h = (h[0] * h[0] + h[1] * h[1]).sqrt();
        Self {
            theta_h: sin_theta_h.atan2(h[2]),
            phi_h: h[1].atan2(h[0]),
            theta_d: (d[0] * d[0] + d[1] * d[1]).sqrt().atan2(d[2]),
            phi_d: d[1].atan2(d[0]),
        }
    }

    /// The direction pair (wi, wo) with these angles; the inverse of [`Self::from_dirs`]. `wo`
    /// is the mirror image of `wi` about the half vector.
    pub fn to_dirs(&self) -> ([f64; 3], [f64; 3]) {
        let (st, ct) = self.theta_d.sin_cos();
        let (sp, cp) = self.phi_d.sin_cos();
        let d = [st * cp, st * sp, ct];
        let d_mirror = [-d[0], -d[1], d[2]];
        (self.half_frame_to_surface(d), self.half_frame_to_surface(d_mirror))
    }

    /// A vector given in the half vector's frame, in the surface frame: rotated by theta_h about
    /// the binormal y, then by phi_h about the normal.
    fn half_frame_to_surface(&self, v: [f64; 3]) -> [f64; 3] {
        let (sh, ch) = self.theta_h.sin_cos();
        let (sp, cp) = self.phi_h.sin_cos();
        let x = ch * v[0] + sh * v[2];
        let z = -sh * v[0] + ch * v[2];
        [cp * x - sp * v[1], sp * x + cp * v[1], z]
    }

    /// phi_d folded into [0, pi) by reciprocity, as MERL stores it.
    #[inline]
    pub fn folded_phi_d(&self) -> f64 {
        fold_phi_d(self.phi_d)
    }

    /// The cell of this pair as MERL's reference reader finds it (truncation of the continuous
    /// indices, clamped to the grid): (theta_h, theta_d, phi_d) indices.
    #[inline]
    pub fn merl_index(&self) -> (usize, usize, usize) {
        (theta_h_index(self.theta_h), theta_d_index(self.theta_d), phi_d_index(self.phi_d))
    }

    /// Continuous (fractional) indices (theta_h, theta_d, phi_d): the integer values are the
    /// sample angles (bin centres) of [`crate::merl::grid`], so cell i is sampled at fractional
    /// index i.
    /// theta_h and theta_d are clamped to [0, 89]; phi_d lies in [0, 180) and wraps (180 = 0).
    #[inline]
    pub fn continuous_index(&self) -> [f64; 3] {
        [
            continuous_theta_h(self.theta_h),
            continuous_theta_d(self.theta_d),
            continuous_phi_d(self.phi_d),
        ]
    }
}

/// The half vector h = normalize(wi + wo) and the difference vector (wi in h's frame).
#[inline]
pub fn half_and_difference(wi: [f64; 3], wo: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let s = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let h = if n > 1e-300 { [s[0] / n, s[1] / n, s[2] / n] } else { [0.0, 0.0, 1.0] };
    // Rotation by -phi_h about z: (cos, sin) of phi_h from h's projection on the surface.
    let sin_theta_h = (h[0] * h[0] + h[1] * h[1]).sqrt();
    let (cp, sp) =
        if sin_theta_h > 0.0 { (h[0] / sin_theta_h, h[1] / sin_theta_h) } else { (1.0, 0.0) };
    let x = cp * wi[0] + sp * wi[1];
    let y = -sp * wi[0] + cp * wi[1];
    // Rotation by -theta_h about y: cos theta_h = h_z.
    let (st, ct) = (sin_theta_h, h[2]);
    let d = [ct * x - st * wi[2], y, st * x + ct * wi[2]];
    (h, d)
}

/// phi_d folded into [0, pi): phi_d and phi_d + pi are the same configuration with wi and wo
/// swapped, and a BRDF is reciprocal.
#[inline]
pub fn fold_phi_d(phi_d: f64) -> f64 {
    let p = phi_d.rem_euclid(PI);
    // rem_euclid can round up to exactly pi for tiny negative inputs.
    if p >= PI {
        0.0
    } else {
        p
    }
}

/// MERL's theta_h index: `floor(sqrt(theta_h / (pi/2)) * 90)`, clamped to [0, 89]
/// (`theta_half_index` in `BRDFRead.cpp`: the square-root warp puts more samples near the
/// specular peak).
#[inline]
pub fn theta_h_index(theta_h: f64) -> usize {
    if theta_h.is_nan() || theta_h <= 0.0 {
        return 0;
    }
    ((theta_h / FRAC_PI_2).sqrt() * N_THETA_H as f64).min((N_THETA_H - 1) as f64) as usize
}

/// MERL's theta_d index: `floor(theta_d / (pi/2) * 90)`, clamped to [0, 89]
/// (`theta_diff_index` in `BRDFRead.cpp`).
#[inline]
pub fn theta_d_index(theta_d: f64) -> usize {
    if theta_d.is_nan() || theta_d <= 0.0 {
        return 0;
    }
    (theta_d / FRAC_PI_2 * N_THETA_D as f64).min((N_THETA_D - 1) as f64) as usize
}

/// MERL's phi_d index: phi_d folded into [0, pi), then `floor(phi_d / pi * 180)`, clamped to
/// [0, 179] (`phi_diff_index` in `BRDFRead.cpp`).
#[inline]
pub fn phi_d_index(phi_d: f64) -> usize {
    if phi_d.is_nan() {
        return 0;
    }
    (fold_phi_d(phi_d) / PI * N_PHI_D as f64).min((N_PHI_D - 1) as f64) as usize
}

/// Fractional theta_h index `sqrt(theta_h / (pi/2)) * 90 - 1/2`, clamped to [0, 89]: the
/// inverse of [`crate::merl::grid::theta_h_of`] (cell i's value stands for its bin centre, at
/// fractional index i).
#[inline]
pub fn continuous_theta_h(theta_h: f64) -> f64 {
    if theta_h.is_nan() || theta_h <= 0.0 {
        return 0.0;
    }
    ((theta_h / FRAC_PI_2).sqrt() * N_THETA_H as f64 - 0.5).clamp(0.0, (N_THETA_H - 1) as f64)
}

/// Fractional theta_d index `theta_d / (pi/2) * 90 - 1/2`, clamped to [0, 89]: the inverse of
/// [`crate::merl::grid::theta_d_of`].
#[inline]
pub fn continuous_theta_d(theta_d: f64) -> f64 {
    if theta_d.is_nan() || theta_d <= 0.0 {
        return 0.0;
    }
    (theta_d / FRAC_PI_2 * N_THETA_D as f64 - 0.5).clamp(0.0, (N_THETA_D - 1) as f64)
}

/// Fractional phi_d index `fold(phi_d) / pi * 180 - 1/2`, wrapped into [0, 180): the inverse of
/// [`crate::merl::grid::phi_d_of`]; phi_d is pi-periodic after folding, so fractional index -1/2
/// (phi_d = 0) lies halfway between cell 179 and cell 0.
#[inline]
pub fn continuous_phi_d(phi_d: f64) -> f64 {
    if phi_d.is_nan() {
        return 0.0;
    }
    let u = (fold_phi_d(phi_d) / PI * N_PHI_D as f64 - 0.5).rem_euclid(N_PHI_D as f64);
    if u >= N_PHI_D as f64 {
        0.0
    } else {
        u
    }
}

/// A unit direction from spherical angles (theta from the normal, phi azimuth).
#[inline]
pub fn direction(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}

/// Wraps an angle into (-pi, pi].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::merl::grid::{phi_d_of, theta_d_of, theta_h_of};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const TOL: f64 = 1e-12;

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
    }

    fn random_upper(rng: &mut ChaCha8Rng) -> [f64; 3] {
        // Uniform on the upper hemisphere: z uniform in (0, 1), phi uniform.
        let z: f64 = rng.random_range(1e-6..1.0);
        let phi: f64 = rng.random_range(-PI..PI);
        direction(z.acos(), phi)
    }

    #[test]
    fn known_angles() {
        let n = [0.0, 0.0, 1.0];
        // Normal incidence and exitance: everything zero.
        let a = HalfDiff::from_dirs(n, n);
        assert!(a.theta_h.abs() < TOL && a.theta_d.abs() < TOL);
        // Mirror configuration: h is the normal, theta_d is the incidence angle.
        let wi = direction(0.7, 0.3);
        let wo = direction(0.7, 0.3 + PI);
        let a = HalfDiff::from_dirs(wi, wo);
        assert!(a.theta_h.abs() < TOL, "{a:?}");
        assert!((a.theta_d - 0.7).abs() < TOL);
        // Normal incidence, exitance at 60 degrees in the x-z plane: h halfway at 30 degrees,
        // and wi is 30 degrees from h on the other side, in h's x-z plane: phi_d = pi.
        let wo = direction(PI / 3.0, 0.0);
        let a = HalfDiff::from_dirs(n, wo);
        assert!((a.theta_h - PI / 6.0).abs() < TOL && a.phi_h.abs() < TOL);
        assert!((a.theta_d - PI / 6.0).abs() < TOL);
        assert!((a.phi_d.abs() - PI).abs() < TOL);
        // Retro-reflection: wi = wo, so h = wi and d is the pole.
        let w = direction(1.1, -2.0);
        let a = HalfDiff::from_dirs(w, w);
        assert!((a.theta_h - 1.1).abs() < TOL && (a.phi_h + 2.0).abs() < TOL);
        assert!(a.theta_d.abs() < 1e-7);
    }

    #[test]
    fn swap_symmetry_and_folding() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..10_000 {
            let (wi, wo) = (random_upper(&mut rng), random_upper(&mut rng));
            let a = HalfDiff::from_dirs(wi, wo);
            let b = HalfDiff::from_dirs(wo, wi);
            assert!((a.theta_h - b.theta_h).abs() < 1e-12);
            assert!((a.theta_d - b.theta_d).abs() < 1e-9);
            assert!(wrap_angle(a.phi_h - b.phi_h).abs() < 1e-9);
            // phi_d shifted by pi: folds to the same value.
            assert!(wrap_angle(a.phi_d - b.phi_d - PI).abs() < 1e-7);
            let (fa, fb) = (a.folded_phi_d(), b.folded_phi_d());
            assert!((fa - fb).abs() < 1e-7 || (fa - fb).abs() > PI - 1e-7);
            let (ia, ib) = (a.merl_index(), b.merl_index());
            // Equal except when the folded angle sits within rounding of a cell edge.
            let edge = (fa / PI * 180.0 - (fa / PI * 180.0).round()).abs() < 1e-6;
            assert!(ia == ib || edge, "{ia:?} vs {ib:?}");
        }
    }

    #[test]
    fn round_trip_dirs_angles_dirs() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..10_000 {
            let (wi, wo) = (random_upper(&mut rng), random_upper(&mut rng));
            let (wi2, wo2) = HalfDiff::from_dirs(wi, wo).to_dirs();
            assert!(close(wi, wi2, 1e-9) && close(wo, wo2, 1e-9), "{wi:?} {wo:?}");
        }
        // And angles -> dirs -> angles.
        for _ in 0..10_000 {
            let a = HalfDiff {
                theta_h: rng.random_range(0.01..1.5),
                phi_h: rng.random_range(-3.1..3.1),
                theta_d: rng.random_range(0.01..1.5),
                phi_d: rng.random_range(-3.1..3.1),
            };
            let (wi, wo) = a.to_dirs();
            let b = HalfDiff::from_dirs(wi, wo);
            let got = [b.theta_h, b.phi_h, b.theta_d, b.phi_d];
            let want = [a.theta_h, a.phi_h, a.theta_d, a.phi_d];
            assert!(got.iter().zip(&want).all(|(x, y)| (x - y).abs() < 1e-9), "{a:?} {b:?}");
        }
    }

    #[test]
    fn merl_index_mapping() {
        // The reference reader's formulas, at a few angles.
        assert_eq!(theta_h_index(0.0), 0);
        assert_eq!(theta_h_index(-1.0), 0);
        assert_eq!(theta_h_index(FRAC_PI_2), 89);
        // sqrt(0.25) * 90 = 45.
        assert_eq!(theta_h_index(FRAC_PI_2 * 0.25 + 1e-12), 45);
        assert_eq!(theta_h_index(FRAC_PI_2 * 0.25 - 1e-9), 44);
        assert_eq!(theta_d_index(FRAC_PI_2 / 90.0 * 30.5), 30);
        assert_eq!(theta_d_index(2.0), 89);
        assert_eq!(phi_d_index(PI / 180.0 * 10.5), 10);
        // Reciprocity: phi_d and phi_d + pi (and -pi) give the same index.
        assert_eq!(phi_d_index(PI / 180.0 * 10.5 + PI), 10);
        assert_eq!(phi_d_index(PI / 180.0 * 10.5 - PI), 10);
        assert_eq!(phi_d_index(-1e-18), 0);
        assert_eq!(phi_d_index(PI - 1e-9), 179);
        // Sample angles of the grid map to their own cells, fractional index = integer index.
        for i in 0..90 {
            let u = continuous_theta_h(theta_h_of(i));
            assert!((u - i as f64).abs() < 1e-9, "{i}: {u}");
            assert!((continuous_theta_d(theta_d_of(i)) - i as f64).abs() < 1e-9);
            // The sample angle is the bin centre: the reference reader's index is the cell, and
            // so it is a third of a bin either side.
            assert_eq!(theta_h_index(theta_h_of(i)), i);
            assert_eq!(theta_d_index(theta_d_of(i)), i);
            let third = FRAC_PI_2 / 90.0 / 3.0;
            assert_eq!(theta_d_index(theta_d_of(i) + third), i);
            assert_eq!(theta_d_index(theta_d_of(i) - third), i);
        }
        for k in 0..180 {
            assert!((continuous_phi_d(phi_d_of(k)) - k as f64).abs() < 1e-9);
            assert_eq!(phi_d_index(phi_d_of(k)), k);
            assert_eq!(phi_d_index(phi_d_of(k) + PI / 180.0 / 3.0), k);
            assert_eq!(phi_d_index(phi_d_of(k) - PI / 180.0 / 3.0), k);
        }
        // phi_d = 0 is the edge between the last and the first cell.
        assert!((continuous_phi_d(0.0) - 179.5).abs() < 1e-9);
        let c = continuous_phi_d(PI - 1e-15);
        assert!((0.0..180.0).contains(&c));
    }
}

//! The microfacet distribution of an isotropic BRDF, retrieved from its retro-reflection as the
//! adaptive parameterization does (Dupuy & Jakob 2018, §4, after Dupuy et al. 2015, "Extracting
//! Microfacet-based BRDF Parameters from Arbitrary Materials with Power Iterations"), and its
//! projected area.
//!
//! A microfacet BRDF with Smith masking reflects back towards the light as
//! `f(w, w) = D(w) / (4 cos(theta) sigma(w))`, where `sigma(w) = integral D(m) <w, m>+ dm` is the
//! projected area of the microsurface. The NDF is therefore the fixed point of
//! `D(w) = f(w, w) cos(theta) sigma[D](w)`, up to scale; being linear and positive in `D`, the
//! map is iterated from a constant (power iteration) until it converges, and `D` is scaled so
//! that `integral D(m) cos(theta_m) dm = sigma(normal) = 1`.
//!
//! Both tables live on the nodes of the RGL files' `ndf` and `sigma` fields: `u_j = j / (N - 1)`
//! with `theta_j = u_j^2 pi / 2` (the square-root warp, fine near the normal where glossy lobes
//! are narrow). Integrals over `m` are trapezoid sums over these nodes in `u`, with the azimuthal
//! integral in closed form, so `sigma` is exactly the integral of the tabulated `D`.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Power iterations at most (each a matrix-vector product of the table's size).
pub const MAX_ITERATIONS: usize = 200;
/// Convergence: the largest change of `D` relative to its maximum.
const TOLERANCE: f64 = 1e-9;
/// Smallest NDF value kept, relative to its maximum: the `rgb` table is stored divided by `D`,
/// which must therefore never vanish where a sample can land.
pub const NDF_FLOOR: f64 = 1e-6;

/// The retrieved microfacet distribution and its projected area on `N` nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Microfacet {
    /// `D(theta_j)` (1/sr), normalised as above.
    pub ndf: Vec<f64>,
    /// `sigma(theta_j)`; `sigma[0] = 1`.
    pub sigma: Vec<f64>,
    /// Power iterations taken.
    pub iterations: usize,
}

/// Polar angle of node `j` of `n`: `(j / (n - 1))^2 pi / 2`.
pub fn node_theta(j: usize, n: usize) -> f64 {
    let u = j as f64 / (n - 1) as f64;
    u * u * FRAC_PI_2
}

/// `integral over phi of max(0, cos a cos b + sin a sin b cos phi)`: the azimuthal part of
/// `<w, m>+` for polar angles `a` (of w) and `b` (of m).
fn azimuthal_cosine(a: f64, b: f64) -> f64 {
    let (p, q) = (a.cos() * b.cos(), a.sin() * b.sin());
    if p >= q {
        TAU * p
    } else if p <= -q {
        0.0
    } else {
        let phi0 = (-p / q).acos();
        2.0 * (p * phi0 + q * phi0.sin())
    }
}

/// The matrix `K` with `sigma_i = sum_j K_ij D_j` (row-major, `n x n`).
fn projected_area_kernel(n: usize) -> Vec<f64> {
    let du = 1.0 / (n - 1) as f64;
    let weight = |j: usize| {
        let u = j as f64 * du;
        let trapezoid = if j == 0 || j == n - 1 { 0.5 * du } else { du };
        // d omega = sin(theta) d theta d phi, d theta = pi u du.
        trapezoid * PI * u * node_theta(j, n).sin()
    };
    let weights: Vec<f64> = (0..n).map(weight).collect();
    let mut k = vec![0.0; n * n];
    for i in 0..n {
        let a = node_theta(i, n);
        for j in 0..n {
            k[i * n + j] = weights[j] * azimuthal_cosine(a, node_theta(j, n));
        }
    }
    k
}

fn apply(k: &[f64], d: &[f64]) -> Vec<f64> {
    k.chunks_exact(d.len()).map(|row| row.iter().zip(d).map(|(a, b)| a * b).sum()).collect()
}

/// Retrieves the NDF from the retro-reflection `retro[j] = f(w_j, w_j)` (luminance, 1/sr) at the
/// `n = retro.len()` nodes, and its projected area. Errors (as text) when the retro-reflection
/// is zero, negative or not finite everywhere it matters, or when fewer than 2 nodes are given.
pub fn retrieve(retro: &[f64]) -> Result<Microfacet, String> {
    let n = retro.len();
    if n < 2 {
        return Err(format!("{n} NDF nodes: at least 2 are needed"));
    }
    if let Some(j) = retro.iter().position(|r| !(r.is_finite() && *r >= 0.0)) {
        return Err(format!(
            "retro-reflection {} at {:.2} deg",
            retro[j],
            node_theta(j, n).to_degrees()
        ));
    }
    let k = projected_area_kernel(n);
    let weight: Vec<f64> = (0..n).map(|j| retro[j] * node_theta(j, n).cos()).collect();
    if !weight.iter().any(|&w| w > 0.0) {
        return Err("the retro-reflection f(w, w) is zero at every angle: no microfacet \
                    distribution can be retrieved (a black material?)"
            .into());
    }
    let normalise = |d: &mut Vec<f64>| -> Result<(), String> {
        let s0: f64 = k[..n].iter().zip(d.iter()).map(|(a, b)| a * b).sum();
        if !(s0.is_finite() && s0 > 0.0) {
            return Err(format!("the NDF integrates to {s0}"));
        }
        d.iter_mut().for_each(|v| *v /= s0);
        Ok(())
    };
    let mut d = vec![1.0; n];
    normalise(&mut d)?;
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let sigma = apply(&k, &d);
        let mut next: Vec<f64> = weight.iter().zip(&sigma).map(|(w, s)| w * s).collect();
        normalise(&mut next)?;
        let max = next.iter().copied().fold(0.0, f64::max);
        let change = next.iter().zip(&d).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        d = next;
        if change <= TOLERANCE * max {
            break;
        }
    }
    let floor = NDF_FLOOR * d.iter().copied().fold(0.0, f64::max);
    d.iter_mut().for_each(|v| *v = v.max(floor));
    normalise(&mut d)?;
    let sigma = apply(&k, &d);
    Ok(Microfacet { ndf: d, sigma, iterations })
}

/// `n >= 2` incidence angles from 0 to pi/2 spaced uniformly in projected area, as the RGL
/// database's files are (`sigma(theta_k) = 1 - k (1 - sigma(pi/2)) / (n - 1)`): denser where the
/// microsurface's visible area changes fastest. `sigma` is read piecewise linearly in `u` between
/// its nodes. Falls back to uniform spacing in `u` where `sigma` is not strictly decreasing
/// enough to give strictly increasing angles.
pub fn incidence_angles(sigma: &[f64], n: usize) -> Vec<f64> {
    let nodes = sigma.len();
    let last = sigma[nodes - 1];
    let inverse = |target: f64| -> Option<f64> {
        let j = sigma.windows(2).position(|w| w[0] >= target && w[1] <= target)?;
        let (a, b) = (sigma[j], sigma[j + 1]);
        let t = if a > b { (a - target) / (a - b) } else { 0.0 };
        let u = (j as f64 + t) / (nodes - 1) as f64;
        Some(u * u * FRAC_PI_2)
    };
    let mut angles = Vec::with_capacity(n);
    for k in 0..n {
        let angle = match k {
            0 => Some(0.0),
            _ if k == n - 1 => Some(FRAC_PI_2),
            _ => inverse(1.0 - k as f64 * (1.0 - last) / (n - 1) as f64),
        };
        angles.push(angle.unwrap_or(f64::NAN));
    }
    let increasing = angles.windows(2).all(|w| w[1] > w[0] + 1e-6);
    if increasing {
        angles
    } else {
        (0..n).map(|k| node_theta(k, n)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The retro-reflection of a GGX microfacet BRDF of roughness `alpha` (with Smith masking
    /// and no Fresnel): `D / (4 cos sigma)`.
    fn ggx_retro(alpha: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let a2 = alpha * alpha;
        let ndf = |t: f64| {
            let c2 = t.cos().powi(2);
            a2 / (PI * (c2 * (a2 - 1.0) + 1.0).powi(2))
        };
        let sigma = |t: f64| {
            // GGX: sigma = cos (1 + Lambda), Lambda = (sqrt(1 + a^2 tan^2) - 1) / 2.
            let tan2 = t.tan().powi(2);
            t.cos() * (1.0 + (-1.0 + (1.0 + a2 * tan2).sqrt()) / 2.0)
        };
        let thetas: Vec<f64> = (0..n).map(|j| node_theta(j, n).min(FRAC_PI_2 - 1e-6)).collect();
        let retro = thetas.iter().map(|&t| ndf(t) / (4.0 * t.cos() * sigma(t))).collect();
        (retro, thetas.iter().map(|&t| ndf(t)).collect())
    }

    #[test]
    fn retrieves_a_ggx_distribution() {
        let n = 128;
        for alpha in [0.1, 0.3, 0.7] {
            let (retro, truth) = ggx_retro(alpha, n);
            let m = retrieve(&retro).expect("retrieve");
            assert!((m.sigma[0] - 1.0).abs() < 1e-12);
            // Within 3% of the true NDF wherever it carries weight (the quadrature's error).
            for j in (0..n - 1).step_by(7) {
                let rel = (m.ndf[j] - truth[j]).abs() / truth[j];
                if truth[j] > 1e-3 * truth[0] {
                    assert!(rel < 0.03, "alpha {alpha} node {j}: {} vs {}", m.ndf[j], truth[j]);
                }
            }
            assert!(m.iterations < MAX_ITERATIONS, "alpha {alpha}: {} iterations", m.iterations);
            assert!(m.sigma.windows(2).all(|w| w[1] <= w[0] + 1e-9));
        }
    }

    #[test]
    fn lambertian_projected_area_and_angles() {
        // A constant f(w, w): D ~ cos sigma; sigma decreasing from 1 to a positive value.
        let m = retrieve(&[1.0; 64]).expect("retrieve");
        assert!(m.sigma[63] > 0.1 && m.sigma[63] < 0.6, "{}", m.sigma[63]);
        let angles = incidence_angles(&m.sigma, 8);
        assert_eq!(angles.len(), 8);
        assert_eq!((angles[0], angles[7]), (0.0, FRAC_PI_2));
        assert!(angles.windows(2).all(|w| w[1] > w[0]), "{angles:?}");
    }

    #[test]
    fn bad_retro_reflections_are_errors() {
        assert!(retrieve(&[0.0; 16]).expect_err("zero").contains("zero at every angle"));
        assert!(retrieve(&[1.0, f64::NAN, 1.0]).expect_err("nan").contains("NaN"));
        assert!(retrieve(&[1.0, -1.0, 1.0]).is_err());
        assert!(retrieve(&[1.0]).is_err());
    }
}

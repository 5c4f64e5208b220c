//! Numerical checks shared by the corpus models' tests: the directional albedo (white-furnace
//! test) by a midpoint rule over the outgoing hemisphere, the normalisation of a microfacet
//! distribution, and reciprocity on fixed pairs.

use crate::merl::coords::direction;
use std::f64::consts::PI;

/// `integral f(wi, wo) cos(theta_o) dwo` over the outgoing hemisphere, for wi at `theta_i`
/// (phi_i = 0): `n` midpoint steps in theta_o, `2 n` in phi_o.
pub fn directional_albedo(
    f: impl Fn([f64; 3], [f64; 3]) -> [f64; 3],
    theta_i: f64,
    n: usize,
) -> [f64; 3] {
    let wi = direction(theta_i, 0.0);
    let (dt, dp) = (PI / 2.0 / n as f64, PI / n as f64);
    let mut sum = [0.0; 3];
    for i in 0..n {
        let t = (i as f64 + 0.5) * dt;
        let w = t.cos() * t.sin() * dt * dp;
        for j in 0..2 * n {
            let v = f(wi, direction(t, (j as f64 + 0.5) * dp));
            for c in 0..3 {
                sum[c] += v[c] * w;
            }
        }
    }
    sum
}

/// `integral D(cos theta) cos(theta) dw` over the hemisphere (midpoint rule, 200,000 steps in
/// theta): 1 for a normalised microfacet distribution.
pub fn projected_integral(d: impl Fn(f64) -> f64) -> f64 {
    let n = 200_000;
    let step = PI / 2.0 / n as f64;
    let sum: f64 = (0..n)
        .map(|i| {
            let t = (i as f64 + 0.5) * step;
            d(t.cos()) * t.cos() * t.sin()
        })
        .sum();
    sum * 2.0 * PI * step
}

/// Asserts `f(a, b) = f(b, a)` (relative 1e-12) on a fixed set of direction pairs.
pub fn assert_reciprocal(f: impl Fn([f64; 3], [f64; 3]) -> [f64; 3]) {
    let pairs = [((0.4, 0.1), (1.0, 2.5)), ((0.05, 0.0), (0.3, 3.0)), ((1.3, -1.0), (0.9, 0.7))];
    for ((ta, pa), (tb, pb)) in pairs {
        let (a, b) = (direction(ta, pa), direction(tb, pb));
        let (fab, fba) = (f(a, b), f(b, a));
        for c in 0..3 {
            let tol = 1e-12 * fab[c].abs().max(1.0);
            assert!((fab[c] - fba[c]).abs() <= tol, "f(a, b) {fab:?} != f(b, a) {fba:?}");
        }
    }
}

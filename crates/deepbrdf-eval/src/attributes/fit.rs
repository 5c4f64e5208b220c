//! Estimating the 7 [`Attributes`] of a tabulated BRDF: a least-squares fit of the Lambertian +
//! GGX model in a cosine-weighted log space, on a fixed subsample of the valid grid cells.
//!
//! The residual of cell `i` and channel `c` is `ln(eps + w_i f_hat) - ln(eps + w_i f)` with
//! `w_i = cos(theta_i) cos(theta_o)` (grazing cells, which the renderer weights by the same
//! cosines, count little; the log keeps the specular peak from dominating). For a fixed roughness
//! the model is linear in the other six parameters (`f_hat = diffuse / pi + specular A + B` with
//! `A = D G (1 - S) / (4 cos_i cos_o)`, `B = D G S / (4 cos_i cos_o)`, `S = (1 - wi.h)^5`), and
//! the channels separate: each channel's two albedos are found by a bounded Gauss-Newton
//! iteration started from the linearised problem's exact minimiser. The roughness is found by
//! minimising that profile error over a log-spaced grid (the "several starts": every grid point
//! is a start, evaluated in parallel) and refining the best bracket by golden-section search.
//! Deterministic: no random numbers, a fixed reduction order.

use super::{cell_directions, Attributes, INV_PI, MAX_ROUGHNESS, MIN_ROUGHNESS};
use crate::error::{EvalError, Result};
use deepbrdf_data::merl::grid::theta_d_of;
use deepbrdf_data::merl::{cell_index, CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use deepbrdf_data::MerlTable;
use deepbrdf_render::geometry::Vec3;
use deepbrdf_render::{Brdf, Ggx};
use rayon::prelude::*;

/// Settings of [`fit`]. The default samples ~35,000 cells of a MERL table (docs/performance.md
/// has its time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitConfig {
    /// Every theta_d index that is a multiple of this is sampled (all 90 theta_h indices are:
    /// the specular peak lives at small theta_h).
    pub theta_d_stride: usize,
    /// Every phi_d index that is a multiple of this is sampled.
    pub phi_d_stride: usize,
    /// Only cells with theta_d below this (degrees) are fitted: MERL's measurements near
    /// grazing are the least reliable, and there Schlick's Fresnel term (-> 1) dominates.
    pub max_theta_d_deg: f64,
    /// `eps` of the log space, in 1/sr.
    pub offset: f64,
    /// Roughness grid points, log-spaced over [MIN_ROUGHNESS, MAX_ROUGHNESS].
    pub grid: usize,
    /// Golden-section steps refining the best grid bracket.
    pub refine_steps: usize,
    /// Gauss-Newton iterations per roughness and channel.
    pub iterations: usize,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            theta_d_stride: 4,
            phi_d_stride: 8,
            max_theta_d_deg: 90.0,
            offset: 1e-3,
            grid: 24,
            refine_steps: 14,
            iterations: 4,
        }
    }
}

impl FitConfig {
    /// The fit that re-estimates the attributes of edited and decoded tables in the editing
    /// measures: the default on a quarter of its cells (theta_d every 8th, phi_d every 16th).
    pub fn quick() -> Self {
        Self { theta_d_stride: 8, phi_d_stride: 16, ..Self::default() }
    }

    fn validate(&self) -> Result<()> {
        let bad = |what: &str| Err(EvalError::Invalid(format!("attribute fit: {what}")));
        if self.theta_d_stride == 0 || self.theta_d_stride > N_THETA_D {
            return bad("theta_d stride must be in 1..=90");
        }
        if self.phi_d_stride == 0 || self.phi_d_stride > N_PHI_D {
            return bad("phi_d stride must be in 1..=180");
        }
        if !(self.offset.is_finite() && self.offset > 0.0) {
            return bad("the log offset must be positive");
        }
        if !(self.max_theta_d_deg > 0.0 && self.max_theta_d_deg <= 90.0) {
            return bad("the theta_d limit must be in (0, 90] degrees");
        }
        if self.grid < 3 {
            return bad("the roughness grid needs at least 3 points");
        }
        Ok(())
    }
}

/// The result of [`fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttributeFit {
    pub attributes: Attributes,
    /// Root mean square of the log-space residuals over the fitted cells and channels.
    pub log_rmse: f64,
    /// Number of cells fitted (sampled cells valid in the table).
    pub cells: usize,
}

/// Fewest valid sampled cells a fit accepts.
const MIN_CELLS: usize = 200;

/// One sampled cell: directions, cosine weight, and the log-space targets per channel.
struct Sample {
    wi: Vec3,
    wo: Vec3,
    w: f64,
    target: [f64; 3],
    /// Weight of the linearised problem, `(w / (eps + w f))^2` per channel.
    lin: [f64; 3],
    value: [f64; 3],
}

/// Fits the model to `table`'s valid cells (see the module documentation).
pub fn fit(table: &MerlTable, config: &FitConfig) -> Result<AttributeFit> {
    config.validate()?;
    let eps = config.offset;
    let mut samples = Vec::new();
    for h in 0..N_THETA_H {
        for d in (0..N_THETA_D).step_by(config.theta_d_stride) {
            if theta_d_of(d).to_degrees() >= config.max_theta_d_deg {
                continue;
            }
            for p in (0..N_PHI_D).step_by(config.phi_d_stride) {
                let cell = cell_index(h, d, p);
                if !table.is_valid(cell) {
                    continue;
                }
                let (wi, wo) = cell_directions(cell);
                let w = wi.z * wo.z;
                if w <= 0.0 {
                    continue;
                }
                let value: [f64; 3] =
                    std::array::from_fn(|c| f64::from(table.values()[c * CELLS + cell]));
                samples.push(Sample {
                    wi,
                    wo,
                    w,
                    target: value.map(|v| (eps + w * v).ln()),
                    lin: value.map(|v| (w / (eps + w * v)).powi(2)),
                    value,
                });
            }
        }
    }
    if samples.len() < MIN_CELLS {
        return Err(EvalError::Invalid(format!(
            "attribute fit: only {} sampled cells are valid (at least {MIN_CELLS} needed)",
            samples.len()
        )));
    }
    let (lo, hi) = (MIN_ROUGHNESS.ln(), MAX_ROUGHNESS.ln());
    let grid: Vec<f64> =
        (0..config.grid).map(|i| lo + (hi - lo) * i as f64 / (config.grid - 1) as f64).collect();
    let profiles: Vec<Profile> =
        grid.par_iter().map(|&la| profile(&samples, la.exp(), config)).collect();
    let best = (0..profiles.len())
        .min_by(|&a, &b| profiles[a].error.total_cmp(&profiles[b].error))
        .expect("the grid has points");
    let mut best_profile = profiles[best];
    // Golden-section search for the minimum of the profile error in ln(alpha) over the bracket
    // around the best grid point.
    let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(grid.len() - 1)]);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - ratio * (b - a);
    let mut x2 = a + ratio * (b - a);
    let mut f1 = profile(&samples, x1.exp(), config);
    let mut f2 = profile(&samples, x2.exp(), config);
    for _ in 0..config.refine_steps {
        if f1.error <= f2.error {
            (b, x2, f2) = (x2, x1, f1);
            x1 = b - ratio * (b - a);
            f1 = profile(&samples, x1.exp(), config);
        } else {
            (a, x1, f1) = (x1, x2, f2);
            x2 = a + ratio * (b - a);
            f2 = profile(&samples, x2.exp(), config);
        }
    }
    for candidate in [f1, f2] {
        if candidate.error < best_profile.error {
            best_profile = candidate;
        }
    }
    let Profile { alpha, diffuse, specular, error } = best_profile;
    let attributes = Attributes { diffuse, specular, roughness: alpha };
    Ok(AttributeFit {
        attributes,
        log_rmse: (error / (3 * samples.len()) as f64).sqrt(),
        cells: samples.len(),
    })
}

/// The best albedos at one roughness and their summed squared residual.
#[derive(Clone, Copy, Debug)]
struct Profile {
    alpha: f64,
    diffuse: [f64; 3],
    specular: [f64; 3],
    error: f64,
}

/// Minimises the log-space error over the six albedos at roughness `alpha`.
fn profile(samples: &[Sample], alpha: f64, config: &FitConfig) -> Profile {
    let alpha = alpha.clamp(MIN_ROUGHNESS, MAX_ROUGHNESS);
    // One renderer evaluation with F0 = (1, 0, 0) gives D G / (4 cos cos) and its Schlick part.
    let lobe = Ggx::new(alpha, [1.0, 0.0, 0.0]);
    let ab: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| {
            let f = lobe.eval(s.wi, s.wo);
            (f[0] - f[1], f[1])
        })
        .collect();
    let mut out = Profile { alpha, diffuse: [0.0; 3], specular: [0.0; 3], error: 0.0 };
    for c in 0..3 {
        let (p, e) = channel(samples, &ab, c, config);
        out.diffuse[c] = p[0];
        out.specular[c] = p[1];
        out.error += e;
    }
    out
}

/// Bounded Gauss-Newton for one channel's (diffuse, specular) in [0, 1]^2; returns them and
/// the summed squared residual.
fn channel(samples: &[Sample], ab: &[(f64, f64)], c: usize, config: &FitConfig) -> ([f64; 2], f64) {
    let eps = config.offset;
    // Start: the exact minimiser of the linearised residual (w (f_hat - f) / (eps + w f)).
    let (mut h, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
    for (s, &(a, b)) in samples.iter().zip(ab) {
        let j = [INV_PI, a];
        let y = s.value[c] - b;
        accumulate(&mut h, &mut g, j, y, s.lin[c]);
    }
    let mut p = minimise_box(h, g);
    let mut e = objective(samples, ab, c, p, eps);
    for _ in 0..config.iterations {
        let (mut h, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
        for (s, &(a, b)) in samples.iter().zip(ab) {
            let m = p[0] * INV_PI + p[1] * a + b;
            let q = s.w / (eps + s.w * m);
            let r = (eps + s.w * m).ln() - s.target[c];
            let j = [q * INV_PI, q * a];
            // Linear model of the residual: r + j . (x - p); minimise |j . x - (j . p - r)|^2.
            accumulate(&mut h, &mut g, j, j[0] * p[0] + j[1] * p[1] - r, 1.0);
        }
        let target = minimise_box(h, g);
        // Backtracking along the segment (inside the box, which is convex).
        let mut t = 1.0;
        let mut improved = false;
        for _ in 0..8 {
            let x = [p[0] + t * (target[0] - p[0]), p[1] + t * (target[1] - p[1])];
            let ex = objective(samples, ab, c, x, eps);
            if ex < e {
                (p, e, improved) = (x, ex, true);
                break;
            }
            t *= 0.5;
        }
        if !improved {
            break;
        }
    }
    (p, e)
}

/// Adds `weight (j . x - y)^2` to the normal equations `h x = g`.
#[inline]
fn accumulate(h: &mut [[f64; 2]; 2], g: &mut [f64; 2], j: [f64; 2], y: f64, weight: f64) {
    for r in 0..2 {
        g[r] += weight * j[r] * y;
        for k in 0..2 {
            h[r][k] += weight * j[r] * j[k];
        }
    }
}

/// Summed squared log-space residual of one channel at albedos `p`.
fn objective(samples: &[Sample], ab: &[(f64, f64)], c: usize, p: [f64; 2], eps: f64) -> f64 {
    samples
        .iter()
        .zip(ab)
        .map(|(s, &(a, b))| {
            let m = p[0] * INV_PI + p[1] * a + b;
            let r = (eps + s.w * m).ln() - s.target[c];
            r * r
        })
        .sum()
}

/// The minimiser over [0, 1]^2 of the convex quadratic `x' h x / 2 - g' x`: the unconstrained
/// minimiser when it lies in the box, else the best of the edge minimisers (each a clamped 1-D
/// problem) and corners.
fn minimise_box(h: [[f64; 2]; 2], g: [f64; 2]) -> [f64; 2] {
    let q = |x: [f64; 2]| {
        0.5 * (h[0][0] * x[0] * x[0] + 2.0 * h[0][1] * x[0] * x[1] + h[1][1] * x[1] * x[1])
            - g[0] * x[0]
            - g[1] * x[1]
    };
    let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    if det > 1e-12 * (h[0][0] * h[1][1]).abs() && det > 0.0 {
        let x = [(h[1][1] * g[0] - h[0][1] * g[1]) / det, (h[0][0] * g[1] - h[1][0] * g[0]) / det];
        if (0.0..=1.0).contains(&x[0]) && (0.0..=1.0).contains(&x[1]) {
            return x;
        }
    }
    let mut best = [0.0, 0.0];
    let mut best_q = q(best);
    for fixed in 0..2 {
        let free = 1 - fixed;
        for bound in [0.0, 1.0] {
            let hff = h[free][free];
            let v = match hff > 0.0 {
                true => ((g[free] - h[free][fixed] * bound) / hff).clamp(0.0, 1.0),
                false => 0.0,
            };
            let mut x = [0.0; 2];
            x[fixed] = bound;
            x[free] = v;
            let qx = q(x);
            if qx < best_q {
                (best, best_q) = (x, qx);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::INVALID_VALUE;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn check(truth: &Attributes, got: &Attributes, what: &str) {
        for c in 0..3 {
            let (d, s) = (got.diffuse[c], got.specular[c]);
            assert!(
                (d - truth.diffuse[c]).abs() <= 0.02 * truth.diffuse[c],
                "{what}: diffuse {c}: {d} vs {}",
                truth.diffuse[c]
            );
            assert!(
                (s - truth.specular[c]).abs() <= 0.02 * truth.specular[c],
                "{what}: specular {c}: {s} vs {}",
                truth.specular[c]
            );
        }
        let r = got.roughness;
        assert!((r - truth.roughness).abs() <= 0.05 * truth.roughness, "{what}: roughness {r}");
    }

    fn materials() -> [Attributes; 3] {
        [
            // A coloured metal-like lobe over a dark base.
            Attributes { diffuse: [0.05, 0.04, 0.02], specular: [0.9, 0.6, 0.3], roughness: 0.15 },
            // A plastic: strong colour, 4% specular, a fairly sharp lobe.
            Attributes { diffuse: [0.6, 0.1, 0.08], specular: [0.04; 3], roughness: 0.05 },
            // Rough and bright.
            Attributes { diffuse: [0.3, 0.35, 0.4], specular: [0.2, 0.25, 0.3], roughness: 0.5 },
        ]
    }

    #[test]
    fn recovers_known_parameters_exactly_from_clean_tables() {
        for truth in materials() {
            let fit = fit(&truth.table(), &FitConfig::default()).unwrap();
            check(&truth, &fit.attributes, "clean");
            assert!(fit.log_rmse < 1e-4, "{truth:?}: log rmse {}", fit.log_rmse);
        }
    }

    #[test]
    fn recovers_known_parameters_under_noise_and_invalid_cells_deterministically() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for truth in materials() {
            let mut values = truth.table().into_values();
            // 5% multiplicative noise per value, and 20% of the valid cells unmeasured.
            for cell in 0..CELLS {
                if values[cell] < 0.0 {
                    continue;
                }
                let drop = rng.random::<f64>() < 0.2;
                for c in 0..3 {
                    let v = &mut values[c * CELLS + cell];
                    *v = match drop {
                        true => INVALID_VALUE,
                        false => *v * (1.0 + 0.05 * (2.0 * rng.random::<f32>() - 1.0)),
                    };
                }
            }
            let table = MerlTable::from_values(values).unwrap();
            let a = fit(&table, &FitConfig::default()).unwrap();
            check(&truth, &a.attributes, "noisy");
            assert!(a.log_rmse > 1e-4, "noise must show in the fit error: {}", a.log_rmse);
            assert_eq!(a, fit(&table, &FitConfig::default()).unwrap(), "not deterministic");
        }
    }

    #[test]
    fn refuses_a_table_without_enough_valid_cells() {
        let values = vec![INVALID_VALUE; deepbrdf_data::merl::VALUES];
        let e = fit(&MerlTable::from_values(values).unwrap(), &FitConfig::default()).unwrap_err();
        assert!(e.to_string().contains("valid"), "{e}");
        let bad = FitConfig { grid: 1, ..FitConfig::default() };
        assert!(fit(&materials()[0].table(), &bad).is_err());
    }

    #[test]
    fn box_minimiser_finds_interior_and_boundary_optima() {
        // h = I: the minimiser is g clamped to the box.
        let i = [[1.0, 0.0], [0.0, 1.0]];
        assert_eq!(minimise_box(i, [0.3, 0.4]), [0.3, 0.4]);
        assert_eq!(minimise_box(i, [-0.3, 2.0]), [0.0, 1.0]);
        // Correlated: unconstrained optimum (-0.5, 1.5) is outside; on x0 = 0 the best x1 is
        // g1 / h11 = 1.25 -> 1, on x1 = 1: x0 = (1 - 0.5) / 1 = 0.5.
        let h = [[1.0, 0.5], [0.5, 1.0]];
        let g = [0.25, 1.25];
        let x = minimise_box(h, g);
        assert!((x[0] - 0.0).abs() < 1e-12 || (x[1] - 1.0).abs() < 1e-12, "{x:?}");
        let q = |x: [f64; 2]| {
            0.5 * (x[0] * x[0] + x[0] * x[1] + x[1] * x[1]) - g[0] * x[0] - g[1] * x[1]
        };
        for a in 0..=20 {
            for b in 0..=20 {
                let y = [a as f64 / 20.0, b as f64 / 20.0];
                assert!(q(x) <= q(y) + 1e-12, "{x:?} worse than {y:?}");
            }
        }
    }
}

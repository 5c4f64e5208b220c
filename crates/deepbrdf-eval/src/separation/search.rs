//! The diffuse search of Sun et al. 2018's separation: for one BRDF, the Lambertian albedo per
//! channel at which the BRDF is best explained as that Lambertian part plus a low-dimensional
//! basis' reconstruction of the rest, the basis that of the collection's specular parts
//! ([`SearchBasis::error`]).
//!
//! The search looks at a regular sample of the domain's cells ([`Sample`]): one albedo per
//! channel is a three-number question, and every `stride`-th cell answers it as well as all of
//! them at a fraction of the cost. The specular parts are mapped as IPCA maps a BRDF
//! ([`crate::ipca::cosine_log_relative`], against the median of the specular parts).

use crate::baseline::Domain;
use crate::error::{EvalError, Result};
use crate::golden::golden_section;
use crate::ipca::{cosine_log_relative_eps, cosine_log_relative_inverse_eps, EPSILON};
use crate::pca::LinearBasis;
use deepbrdf_data::merl::{grid::cos_weights, CELLS};
use deepbrdf_data::{MerlTable, Silent};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Points of the coarse grid over an albedo's range, before the golden-section refinement.
const GRID: usize = 10;
/// Golden-section steps after the grid (the bracket shrinks to 0.618^12 ~ 3e-3 of itself).
const GOLDEN_STEPS: usize = 12;
/// Sweeps of the three channels in turn (each channel's best albedo moves the others').
const SWEEPS: usize = 3;

/// `pi` times each channel's smallest value of `table` over `domain`: the largest albedo that
/// leaves no specular value below zero (Sun et al. 2018's constraint), the separation's bound
/// and its starting point.
pub fn lowest_albedos(domain: &Domain, table: &MerlTable) -> [f64; 3] {
    let v = table.values();
    std::array::from_fn(|c| {
        let lowest = domain
            .cells()
            .iter()
            .filter(|&&cell| table.is_valid(cell as usize))
            .map(|&cell| f64::from(v[c * CELLS + cell as usize]))
            .fold(f64::INFINITY, f64::min);
        if lowest.is_finite() {
            PI * lowest.max(0.0)
        } else {
            0.0
        }
    })
}

/// Every `stride`-th cell of a domain, with its cosine weight `cos(theta_i) cos(theta_o)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    cells: Vec<u32>,
    weights: Vec<f64>,
}

impl Sample {
    /// Every `stride`-th cell of `domain` (the first one included).
    pub fn new(domain: &Domain, stride: usize) -> Result<Self> {
        if stride == 0 {
            return Err(EvalError::Invalid("the separation's cell stride must be positive".into()));
        }
        let cells: Vec<u32> = domain.cells().iter().step_by(stride).copied().collect();
        let all = cos_weights();
        let weights = cells.iter().map(|&c| f64::from(all[c as usize])).collect();
        Ok(Self { cells, weights })
    }

    /// Number of sampled cells (a row of the search holds three times as many values).
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Whether no cell is sampled.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// `table`'s values at the sampled cells, channel-major (NaN where it has no measurement).
    pub fn values(&self, table: &MerlTable) -> Vec<f32> {
        let v = table.values();
        let mut out = Vec::with_capacity(3 * self.len());
        for c in 0..3 {
            out.extend(self.cells.iter().map(|&cell| {
                let cell = cell as usize;
                if table.is_valid(cell) {
                    v[c * CELLS + cell]
                } else {
                    f32::NAN
                }
            }));
        }
        out
    }
}

/// The basis the search measures specular parts against: the median of the collection's
/// specular parts (the mapping's reference) and their first principal components, on a
/// [`Sample`]'s cells.
#[derive(Clone, Debug, PartialEq)]
pub struct SearchBasis {
    reference: Vec<f32>,
    basis: LinearBasis,
    /// eps of the specular part's mapping.
    epsilon: f64,
}

impl SearchBasis {
    /// Fits `components` principal components to the specular parts of `values` (one sample
    /// row per material) with diffuse albedos `albedos`.
    pub fn fit(
        sample: &Sample,
        values: &[&[f32]],
        albedos: &[[f64; 3]],
        components: usize,
        epsilon: f64,
    ) -> Result<Self> {
        let n = sample.len();
        let dim = 3 * n;
        // The mapping's reference: the median of the specular parts, value by value.
        let reference: Vec<f32> = (0..dim)
            .into_par_iter()
            .map(|i| {
                let mut at: Vec<f32> = values
                    .iter()
                    .zip(albedos)
                    .filter(|(v, _)| v[i].is_finite())
                    .map(|(v, a)| (f64::from(v[i]) - a[i / n] / PI) as f32)
                    .collect();
                deepbrdf_data::mapping::median(&mut at).max(0.0)
            })
            .collect();
        let rows: Vec<Vec<f32>> = values
            .iter()
            .zip(albedos)
            .map(|(v, a)| map_row(sample, v, &reference, *a, epsilon))
            .collect();
        let mean = column_means(&rows, dim);
        let rows: Vec<Vec<f32>> = rows
            .into_iter()
            .map(|r| {
                r.into_iter().zip(&mean).map(|(x, &m)| if x.is_nan() { m } else { x }).collect()
            })
            .collect();
        let refs: Vec<&[f32]> = rows.iter().map(Vec::as_slice).collect();
        let basis = LinearBasis::fit(&refs, components, &Silent)?;
        Ok(Self { reference, basis, epsilon })
    }

    /// The albedo per channel at which `values` is best explained as that Lambertian part
    /// plus the basis' reconstruction of the rest ([`SearchBasis::error`]), within `[0,
    /// bounds]` ([`lowest_albedos`]): the three bounds scaled together first, then each
    /// channel in turn, [`SWEEPS`] times (each a grid, then golden sections round its best).
    pub fn separate(&self, sample: &Sample, values: &[f32], bounds: [f64; 3]) -> [f64; 3] {
        // First all channels together, as a fraction of their bounds: one channel searched
        // while the others sit at their bounds sees the wrong landscape.
        let t = minimise(|t| self.error(sample, values, bounds.map(|b| t * b)), 1.0);
        let mut albedo = bounds.map(|b| t * b);
        for _ in 0..SWEEPS {
            for c in 0..3 {
                let cost = |a: f64| {
                    let mut trial = albedo;
                    trial[c] = a;
                    self.error(sample, values, trial)
                };
                albedo[c] = minimise(cost, bounds[c]);
            }
        }
        albedo
    }

    /// How far `values` is from the Lambertian part of `albedo` plus the basis' reconstruction
    /// of the specular part: the squared differences of `ln(rho w + eps)` over the sample.
    /// Measured on the whole BRDF, a diffuse part the specular basis has to carry costs what
    /// the basis fails to reconstruct of it, and the specular tails a Lambertian part hides
    /// cost nothing, so the error is smallest where the split is (a residual of the specular
    /// part alone is smallest where much of the Lambertian part is left in it).
    pub fn error(&self, sample: &Sample, values: &[f32], albedo: [f64; 3]) -> f64 {
        let n = sample.len();
        let k = self.basis.k();
        let (mean, comps) = (self.basis.mean(), self.basis.components());
        let mut coefficients = vec![0f64; k];
        for (i, &x) in values.iter().enumerate() {
            if x.is_finite() {
                let (r, w) = (self.reference[i], sample.weights[i % n]);
                let y = specular_mapped(x, albedo[i / n], r, w, self.epsilon);
                let d = y - f64::from(mean[i]);
                for (t, &v) in coefficients.iter_mut().zip(&comps[i * k..(i + 1) * k]) {
                    *t += d * f64::from(v);
                }
            }
        }
        let mut error = 0.0;
        for (i, &x) in values.iter().enumerate() {
            if !x.is_finite() {
                continue;
            }
            let along: f64 = coefficients
                .iter()
                .zip(&comps[i * k..(i + 1) * k])
                .map(|(t, &v)| t * f64::from(v))
                .sum();
            let w = sample.weights[i % n];
            let y = f64::from(mean[i]) + along;
            let r = f64::from(self.reference[i]);
            let specular = cosine_log_relative_inverse_eps(y, r, w, self.epsilon);
            let rho_hat = (albedo[i / n] / PI + specular).max(0.0);
            let e = ((rho_hat * w + EPSILON) / (f64::from(x) * w + EPSILON)).ln();
            error += e * e;
        }
        error
    }
}

/// The argument of the smallest `cost` over `[0, upper]`: a grid of [`GRID`] points, then
/// golden sections within the grid step on each side of its best point.
fn minimise(cost: impl Fn(f64) -> f64, upper: f64) -> f64 {
    if upper <= 0.0 {
        return 0.0;
    }
    let step = upper / (GRID - 1) as f64;
    let (mut best_x, mut best) = (0.0, f64::INFINITY);
    for i in 0..GRID {
        let x = step * i as f64;
        let f = cost(x);
        if f < best {
            (best_x, best) = (x, f);
        }
    }
    let (lo, hi) = ((best_x - step).max(0.0), (best_x + step).min(upper));
    let (x, f) = golden_section(cost, lo, hi, GOLDEN_STEPS);
    if f < best {
        best_x = x;
    }
    best_x
}

/// The mapped specular row of sample `values` with albedo `a` (NaN where there is no value).
fn map_row(sample: &Sample, values: &[f32], reference: &[f32], a: [f64; 3], eps: f64) -> Vec<f32> {
    let n = sample.len();
    (0..3 * n)
        .map(|i| {
            let x = values[i];
            if !x.is_finite() {
                return f32::NAN;
            }
            specular_mapped(x, a[i / n], reference[i], sample.weights[i % n], eps) as f32
        })
        .collect()
}

/// The specular part `rho - albedo / pi` of a value, mapped as IPCA maps a value (weight `w`).
#[inline]
fn specular_mapped(rho: f32, albedo: f64, reference: f32, w: f64, eps: f64) -> f64 {
    cosine_log_relative_eps(f64::from(rho) - albedo / PI, f64::from(reference), w, eps)
}

/// The mean of each column over the rows where it is not NaN (0 where it is NaN in all).
fn column_means(rows: &[Vec<f32>], dim: usize) -> Vec<f32> {
    (0..dim)
        .map(|i| {
            let (s, n) = rows
                .iter()
                .map(|r| r[i])
                .filter(|x| !x.is_nan())
                .fold((0f64, 0usize), |(s, n), x| (s + f64::from(x), n + 1));
            if n == 0 {
                0.0
            } else {
                (s / n as f64) as f32
            }
        })
        .collect()
}

/// Separates every BRDF of `values` (with its `bounds`) against `search`, in parallel.
pub fn separate_all(
    search: &SearchBasis,
    sample: &Sample,
    values: &[&[f32]],
    bounds: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    values.par_iter().zip(bounds).map(|(v, &b)| search.separate(sample, v, b)).collect()
}

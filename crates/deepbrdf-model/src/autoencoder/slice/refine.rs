//! Encoding by optimisation: the latent vector that minimises the eq. (4) error of
//! the decoder's output (eq. 3) against the BRDF being encoded, found by Levenberg-Marquardt
//! from the encoder's answer (eq. 2).
//!
//! The encoder f is amortised: trained on the training BRDFs, it can land far from the best
//! latent of a BRDF it has never seen (docs/model.md). Encoding is a small problem for the `slice`
//! network: k unknowns, the error a sum of squares over its 540 x M output coefficients
//! ([`super::step`]: for an orthonormal slice basis the mapped error is the
//! coefficients' squared error plus a fixed residual), and the decoder costs a few milliseconds,
//! so the Jacobian is taken by forward differences, all k + 1 decodes in one batch, and the
//! damped Gauss-Newton step solved in f64. The decoder's MLP is piecewise linear (leaky ReLU),
//! so the differences are exact inside a linear piece. A step is kept only if it lowers the
//! error: the result is never worse than the better of the two starts (the encoder's latent and
//! the principal-component latent `c[..k]`, which is PCA within the basis' span).

use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::layout::{layout_index, PLANE};
use deepbrdf_data::mapping::EPSILON;
use deepbrdf_data::merl::grid::cos_weights;
use deepbrdf_data::merl::{cell_index, CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use nalgebra::{DMatrix, DVector};

use super::network::SliceNetwork;
use crate::error::{ModelError, Result};

/// How an encoding is refined: `iterations` Levenberg-Marquardt steps (0: the encoder alone),
/// on the error weighted by `radiance_power` ([`image_metric`]; 0: eq. (4)'s mapped error).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refinement {
    pub iterations: usize,
    pub radiance_power: f64,
}

impl Default for Refinement {
    /// 20 steps of the mapped error: on held-out `merl` materials the error stops moving after
    /// one to a few steps.
    fn default() -> Self {
        Self { iterations: 20, radiance_power: 0.0 }
    }
}

impl Refinement {
    /// No refinement: the encoder's latent as it is.
    pub const NONE: Self = Self { iterations: 0, radiance_power: 0.0 };
}

/// The metric of a radiance-weighted refinement: `L^T` with `L L^T = B diag(w) B^T` (M x M), so
/// that `|L^T (g - a)|^2` is the error of an image's coefficients `g` against `a` weighted per
/// (theta_h, theta_d) cell by `w`. A cell's weight is the mean, over its valid phi_d and
/// colour values, of `((rho + rho_ref + 2 eps) cos theta_i cos theta_o)^(2 power)`: the first
/// factor is `d rho / d y` of eq. (1) at the value encoded, so `power = 1` weighs the error as
/// a cosine-weighted error of the linear BRDF (what a rendering sees) and `power = 0` as eq.
/// (4)'s mapped error; weights are scaled to mean 1 and floored at 1e-3 of it.
///
/// `layout`: the mapped input (540 x 90 x 90, invalid cells 0), `mask` its validity,
/// `reference`: eq. (1)'s reference in MERL order, `basis`: the slice basis (M x 8100).
pub(crate) fn image_metric(
    layout: &[f32],
    mask: &[f32],
    reference: &[f32],
    basis: &[f32],
    power: f64,
) -> Result<DMatrix<f64>> {
    let m = basis.len() / PLANE;
    if m == 0 || basis.len() != m * PLANE || reference.len() != 3 * CELLS {
        return Err(ModelError::Invalid(format!(
            "a radiance metric needs a slice basis of M x {PLANE} values and a reference of {} \
             (got {} and {})",
            3 * CELLS,
            basis.len(),
            reference.len()
        )));
    }
    let cos = cos_weights();
    let mut weights = vec![0f64; PLANE];
    for h in 0..N_THETA_H {
        for d in 0..N_THETA_D {
            let (mut sum, mut count) = (0f64, 0usize);
            for p in 0..N_PHI_D {
                let cell = cell_index(h, d, p);
                for c in 0..3 {
                    let i = layout_index(h, d, p, c);
                    if mask[i] > 0.0 {
                        let slope = (f64::from(reference[c * CELLS + cell]) + EPSILON)
                            * f64::from(layout[i]).exp();
                        let radiance = slope * f64::from(cos[cell]).max(0.0);
                        sum += radiance.powf(2.0 * power);
                        count += 1;
                    }
                }
            }
            weights[h * N_THETA_D + d] = if count > 0 { sum / count as f64 } else { 0.0 };
        }
    }
    let valid: Vec<f64> = weights.iter().copied().filter(|w| *w > 0.0).collect();
    let mean = valid.iter().sum::<f64>() / valid.len().max(1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return Err(ModelError::Invalid(format!("radiance weights are not usable (mean {mean})")));
    }
    let weights: Vec<f64> = weights.iter().map(|w| (w / mean).max(1e-3)).collect();
    let mut gram = DMatrix::<f64>::zeros(m, m);
    for a in 0..m {
        let row_a = &basis[a * PLANE..(a + 1) * PLANE];
        for b in 0..=a {
            let row_b = &basis[b * PLANE..(b + 1) * PLANE];
            let v: f64 = row_a
                .iter()
                .zip(row_b)
                .zip(&weights)
                .map(|((x, y), w)| f64::from(*x) * f64::from(*y) * w)
                .sum();
            gram[(a, b)] = v;
            gram[(b, a)] = v;
        }
    }
    let chol = gram.cholesky().ok_or_else(|| {
        ModelError::Invalid("the radiance-weighted Gram matrix is not positive definite".into())
    })?;
    Ok(chol.l().transpose())
}

/// Each image's M coefficients of `values` (`540 M`) multiplied by `metric` (M x M).
fn transformed(values: &[f32], metric: Option<&DMatrix<f64>>) -> Vec<f32> {
    let Some(metric) = metric else { return values.to_vec() };
    let m = metric.nrows();
    let mut out = vec![0f32; values.len()];
    for (image, o) in values.chunks(m).zip(out.chunks_mut(m)) {
        for (a, slot) in o.iter_mut().enumerate() {
            *slot = (0..m).map(|b| metric[(a, b)] * f64::from(image[b])).sum::<f64>() as f32;
        }
    }
    out
}

/// Forward-difference step of latent value j: relative to the latent's scale, large enough that
/// f32 rounding of the outputs (~1e-7 of coefficients of order 100) stays far below it.
fn difference_step(z: &[f32]) -> f32 {
    let rms = (z.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>() / z.len().max(1) as f64).sqrt();
    (1e-3 * (1.0 + rms)) as f32
}

/// The decoded coefficients of each latent vector in `latents` (`[n][k]`), `[n][540 M]`, in
/// the refinement's metric.
fn decode_all(
    net: &SliceNetwork,
    latents: &[Vec<f32>],
    metric: Option<&DMatrix<f64>>,
    device: &Device,
) -> Result<Vec<Vec<f32>>> {
    let (n, k) = (latents.len(), net.latent());
    let flat: Vec<f32> = latents.iter().flatten().copied().collect();
    let z = Tensor::<2>::from_data(TensorData::new(flat, [n, k]), device);
    let out = crate::read_back::values(net.decode_coefficients(z), "the decoded coefficients")?;
    let len = net.coefficient_len();
    Ok(out.chunks(len).map(|c| transformed(c, metric)).collect())
}

/// Squared error of `output` against `target`.
fn squared_error(output: &[f32], target: &[f32]) -> f64 {
    output.iter().zip(target).map(|(o, t)| (f64::from(*o) - f64::from(*t)).powi(2)).sum()
}

/// The latent among `starts` and its refinements with the lowest squared coefficient error
/// against `target` (`540 M` values: the input's coefficients), in `metric` when given
/// ([`image_metric`]), and that error.
pub(crate) fn refine(
    net: &SliceNetwork,
    target: &[f32],
    starts: &[Vec<f32>],
    refinement: Refinement,
    metric: Option<&DMatrix<f64>>,
    device: &Device,
) -> Result<(Vec<f32>, f64)> {
    let k = net.latent();
    if target.len() != net.coefficient_len()
        || starts.is_empty()
        || starts.iter().any(|s| s.len() != k)
    {
        return Err(ModelError::Invalid(format!(
            "refinement needs {} target coefficients and starts of k = {k} values",
            net.coefficient_len()
        )));
    }
    if metric.is_some_and(|m| m.nrows() != net.directions() || m.ncols() != net.directions()) {
        return Err(ModelError::Invalid(format!(
            "a refinement metric must be {0} x {0}",
            net.directions()
        )));
    }
    let target = transformed(target, metric);
    let target = &target[..];
    let outputs = decode_all(net, starts, metric, device)?;
    let (mut z, mut output, mut error) = starts
        .iter()
        .zip(outputs)
        .map(|(s, o)| {
            let e = squared_error(&o, target);
            (s.clone(), o, e)
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .expect("starts is not empty");
    let mut damping = 1e-3f64;
    for _ in 0..refinement.iterations {
        let h = difference_step(&z);
        let probes: Vec<Vec<f32>> = (0..k)
            .map(|j| {
                let mut p = z.clone();
                p[j] += h;
                p
            })
            .collect();
        let probed = decode_all(net, &probes, metric, device)?;
        // J^T J and J^T r with J's column j = (g(z + h e_j) - g(z)) / h, r = g(z) - target.
        let columns: Vec<Vec<f64>> = probed
            .iter()
            .map(|p| {
                p.iter()
                    .zip(&output)
                    .map(|(a, b)| (f64::from(*a) - f64::from(*b)) / f64::from(h))
                    .collect()
            })
            .collect();
        let residual: Vec<f64> =
            output.iter().zip(target).map(|(o, t)| f64::from(*o) - f64::from(*t)).collect();
        let mut jtj = DMatrix::<f64>::zeros(k, k);
        let mut jtr = DVector::<f64>::zeros(k);
        for a in 0..k {
            jtr[a] = columns[a].iter().zip(&residual).map(|(j, r)| j * r).sum();
            for b in 0..=a {
                let v: f64 = columns[a].iter().zip(&columns[b]).map(|(x, y)| x * y).sum();
                jtj[(a, b)] = v;
                jtj[(b, a)] = v;
            }
        }
        // Damped steps until one lowers the error (at most a few tries per iteration).
        let mut improved = false;
        for _ in 0..8 {
            let mut system = jtj.clone();
            for a in 0..k {
                system[(a, a)] += damping * jtj[(a, a)].max(1e-12);
            }
            let Some(step) = system.cholesky().map(|c| c.solve(&(-&jtr))) else {
                damping *= 4.0;
                continue;
            };
            let candidate: Vec<f32> =
                z.iter().zip(step.iter()).map(|(v, s)| v + *s as f32).collect();
            if candidate.iter().any(|v| !v.is_finite()) {
                damping *= 4.0;
                continue;
            }
            let out = decode_all(net, std::slice::from_ref(&candidate), metric, device)?.remove(0);
            let e = squared_error(&out, target);
            if e < error {
                (z, output, error) = (candidate, out, e);
                damping = (damping / 3.0).max(1e-9);
                improved = true;
                break;
            }
            damping *= 4.0;
        }
        if !improved {
            break;
        }
    }
    Ok((z, error))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autoencoder::{Architecture, AutoencoderConfig, SliceConfig};
    use deepbrdf_data::layout::LAYOUT_VALUES;

    const M: usize = 4;
    const K: usize = 6;

    fn device() -> Device {
        Default::default()
    }

    /// Rows `e_{at(j)}` of `len` values: orthonormal.
    fn unit_rows(rows: usize, len: usize, at: impl Fn(usize) -> usize) -> Vec<f32> {
        let mut v = vec![0f32; rows * len];
        for j in 0..rows {
            v[j * len + at(j)] = 1.0;
        }
        v
    }

    /// A small `slice` network (M = 4, K = 6, k = 3) with a unit-vector basis and components;
    /// its decoder MLP starts at zero, so it decodes `mean + P[..k]^T z`.
    fn network() -> SliceNetwork {
        let slice = SliceConfig::new().with_directions(M).with_components(K).with_hidden(Some(8));
        let config = AutoencoderConfig::new(3, Architecture::Slice(slice));
        let model = config.init(&device()).unwrap();
        let len = 540 * M;
        let basis = unit_rows(M, PLANE, |j| 97 * j + 5);
        let mean: Vec<f32> = (0..len).map(|i| ((i % 13) as f32 - 6.0) * 0.1).collect();
        let components = unit_rows(K, len, |j| 311 * j + 2);
        model.slice().unwrap().clone().with_fit(&basis, &mean, &components).unwrap()
    }

    fn decoded(net: &SliceNetwork, z: &[f32]) -> Vec<f32> {
        decode_all(net, &[z.to_vec()], None, &device()).unwrap().remove(0)
    }

    #[test]
    fn refinement_finds_the_latent_of_a_decoded_target_and_is_never_worse_than_its_start() {
        let net = network();
        let truth = [1.5f32, -2.0, 0.75];
        let target = decoded(&net, &truth);
        let start = vec![0f32; 3];
        let first = squared_error(&decoded(&net, &start), &target);
        let steps = Refinement::default();
        let (z, error) = refine(&net, &target, &[start.clone()], steps, None, &device()).unwrap();
        assert!(error < 1e-8 * first, "{error} vs {first}");
        for (a, b) in z.iter().zip(&truth) {
            assert!((a - b).abs() < 1e-3, "{z:?} vs {truth:?}");
        }
        // No steps: the better of the starts, as it is.
        let (z, error) =
            refine(&net, &target, &[start, truth.to_vec()], Refinement::NONE, None, &device())
                .unwrap();
        assert_eq!((z, error), (truth.to_vec(), 0.0));
        // Wrong sizes are errors, not panics.
        assert!(refine(&net, &target[1..], &[truth.to_vec()], steps, None, &device()).is_err());
        assert!(refine(&net, &target, &[vec![0.0; 2]], steps, None, &device()).is_err());
        assert!(refine(&net, &target, &[], steps, None, &device()).is_err());
    }

    #[test]
    fn the_radiance_metric_weighs_cells_by_their_cosines_and_values() {
        // A constant mapped input and reference: a cell's weight is its mean squared cosine
        // product (power 1), relative to the others.
        let layout = vec![0.7f32; LAYOUT_VALUES];
        let mask = vec![1f32; LAYOUT_VALUES];
        let reference = vec![0.05f32; 3 * CELLS];
        let cells = [(2usize, 3usize), (40, 60)];
        let basis = unit_rows(2, PLANE, |j| cells[j].0 * N_THETA_D + cells[j].1);
        let flat = image_metric(&layout, &mask, &reference, &basis, 0.0).unwrap();
        assert!((&flat - DMatrix::<f64>::identity(2, 2)).abs().max() < 1e-9, "{flat}");
        let metric = image_metric(&layout, &mask, &reference, &basis, 1.0).unwrap();
        assert!(metric[(0, 1)].abs() < 1e-12 && metric[(1, 0)].abs() < 1e-12, "{metric}");
        let cos = cos_weights();
        let mean_sq = |(h, d): (usize, usize)| {
            (0..N_PHI_D).map(|p| f64::from(cos[cell_index(h, d, p)]).max(0.0).powi(2)).sum::<f64>()
        };
        let want = mean_sq(cells[0]) / mean_sq(cells[1]);
        let got = (metric[(0, 0)] / metric[(1, 1)]).powi(2);
        assert!((got / want - 1.0).abs() < 1e-6, "{got} vs {want}");
        // A refinement in that metric still finds a decoded target's latent.
        let net = network();
        let basis = net.basis_values().unwrap();
        let metric = image_metric(&layout, &mask, &reference, &basis, 0.5).unwrap();
        let truth = [0.5f32, 1.0, -1.0];
        let target = decoded(&net, &truth);
        let steps = Refinement { iterations: 5, radiance_power: 0.5 };
        let start = vec![vec![0f32; 3]];
        let (z, _) = refine(&net, &target, &start, steps, Some(&metric), &device()).unwrap();
        for (a, b) in z.iter().zip(&truth) {
            assert!((a - b).abs() < 1e-3, "{z:?} vs {truth:?}");
        }
        assert!(image_metric(&layout, &mask, &reference[1..], &basis, 0.5).is_err());
    }
}

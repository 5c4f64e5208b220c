//! The fixed linear parts of the `slice` network ([`super::network`]; not in the paper): one
//! basis of M directions for a single (theta_h, theta_d) image of the §3.2 layout, shared by
//! all 540 images (180 phi_d slices x 3 colours) of every BRDF, and the principal components of
//! the BRDFs' coefficients in it.
//!
//! - [`fit_slice_basis`]: the M leading principal directions (uncentred, so the mean shape is
//!   in the span) of the masked mapped images of a training set (every third phi_d slice)
//!   (eq. (1) space, invalid cells 0), found by randomized subspace iteration (Halko et al.
//!   2011): the 8100 x 8100 second moment `sum_i X_i^T X_i` is applied to a block of vectors a
//!   few times, never formed. The images of a training set are many more samples of 8100
//!   values than its BRDFs are of whole tables.
//! - [`pixel_weights`]: the weight of each (theta_h, theta_d) cell in the basis' error, more at
//!   the highlight's centre. The basis is the principal directions U of the images scaled by
//!   `sqrt(w)`; its rows are stored as the synthesis directions `S = U / sqrt(w)` (an image is
//!   `S^T a`) and a layout's coefficients are `a = (w x) S^T`, so the coefficients' squared
//!   error is the cells' error weighted by `w`: the training loss and the encoding's
//!   refinement, which work on coefficients, weigh the centre as the basis does. Few cells
//!   carry the centre of a highlight (theta_h bins 0-2 span 0.1 deg) and eq. (1) divides them
//!   by the training median's peak, so unweighted, a low-rank fit's error there is small in
//!   the mapped space and a dark or tinted dot in a rendering.
//! - [`project`]: the 540 x M coefficients of one layout and its squared (weighted) distance
//!   to the span.
//! - [`fit_components`]: the leading principal directions of the coefficient vectors (the Gram
//!   route of [`deepbrdf_data::gram_pca`]), the network's linear path: with its MLPs at zero the
//!   network is PCA in the mapped space restricted to the slice basis' span.
//!
//! All sums run in a fixed order: the fits are deterministic bit for bit.

use burn::prelude::*;
use burn::tensor::TensorData;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::error::{ModelError, Result};
use deepbrdf_data::gram_pca::{leading_eigenpairs, ordered_block_sum};
use deepbrdf_data::layout::{
    LAYOUT_VALUES, PLANE, SIDE, SLICE_CHANNELS as INPUT_CHANNELS, SLICE_VALUES,
};

/// Extra vectors of the subspace iteration beyond M (oversampling).
const OVERSAMPLING: usize = 16;
/// Applications of the second moment (the last one feeds the Rayleigh-Ritz step).
const PASSES: usize = 3;
/// The basis is fitted to the images of every third phi_d slice (18,000 images of 100 BRDFs:
/// plenty for M directions of 8100 values; neighbouring slices are nearly equal).
const FIT_SLICE_STRIDE: usize = 3;
/// BRDFs whose images are multiplied at once.
const GROUP: usize = 8;

/// A row-major f32 tensor of the column-major `m`.
fn tensor_of(m: &DMatrix<f64>, device: &Device) -> Tensor<2> {
    let values: Vec<f32> = m.transpose().iter().map(|&v| v as f32).collect();
    Tensor::from_data(TensorData::new(values, [m.nrows(), m.ncols()]), device)
}

/// The images of `layouts` stacked: `[540 * layouts, 8100]`.
fn images(layouts: &[&[f32]], device: &Device) -> Tensor<2> {
    let values: Vec<f32> = layouts.iter().flat_map(|l| l.iter().copied()).collect();
    Tensor::from_data(TensorData::new(values, [INPUT_CHANNELS * layouts.len(), PLANE]), device)
}

/// The weight of each of the [`PLANE`] cells of an image (theta_h row, theta_d column):
/// `1 + emphasis / (1 + theta_h index)`, so that theta_h bin 0 weighs `1 + emphasis` and the
/// rows past a few degrees about 1 (`emphasis` 0: all 1, the unweighted basis).
pub fn pixel_weights(emphasis: f64) -> Vec<f32> {
    (0..PLANE).map(|p| (1.0 + emphasis / (1 + p / SIDE) as f64) as f32).collect()
}

/// The images of every [`FIT_SLICE_STRIDE`]-th slice of `layouts`, stacked, each cell scaled by
/// `scale`.
fn strided_images(layouts: &[&[f32]], scale: &[f32], device: &Device) -> Tensor<2> {
    let values: Vec<f32> = layouts
        .iter()
        .flat_map(|l| l.chunks(SLICE_VALUES).step_by(FIT_SLICE_STRIDE).flatten().copied())
        .zip(scale.iter().cycle())
        .map(|(v, s)| v * s)
        .collect();
    let rows = values.len() / PLANE;
    Tensor::from_data(TensorData::new(values, [rows, PLANE]), device)
}

fn read(t: Tensor<2>) -> Result<Vec<f32>> {
    crate::read_back::values(t, "the slice basis fit's product")
}

/// `sum_i X_i^T (X_i q)` over the layouts (cells scaled by `scale`), in f64, added group by
/// group in layout order.
fn second_moment_times(
    layouts: &[&[f32]],
    scale: &[f32],
    q: &DMatrix<f64>,
    device: &Device,
) -> Result<DMatrix<f64>> {
    let q32 = tensor_of(q, device); // [8100, L]
    let mut total = DMatrix::<f64>::zeros(q.nrows(), q.ncols());
    for group in layouts.chunks(GROUP) {
        let x = strided_images(group, scale, device); // [180 g, 8100]
        let part = read(x.clone().transpose().matmul(x.matmul(q32.clone())))?; // [8100, L]
        for (i, v) in part.iter().enumerate() {
            total[(i / q.ncols(), i % q.ncols())] += f64::from(*v);
        }
    }
    Ok(total)
}

/// An orthonormal basis of the columns of `y` (thin QR).
fn orthonormal(y: DMatrix<f64>) -> DMatrix<f64> {
    y.qr().q()
}

/// The `m` leading directions of the images of `layouts` (each `540 * 90 * 90` mapped values in
/// layout order, invalid cells 0) under the cell weights `weights` ([`pixel_weights`]): `m`
/// rows of [`PLANE`] values, row-major, the synthesis directions `U / sqrt(w)` (orthonormal
/// under the inner product weighted by `w`; orthonormal when every weight is 1).
pub fn fit_slice_basis(
    layouts: &[&[f32]],
    m: usize,
    weights: &[f32],
    seed: u64,
    device: &Device,
) -> Result<Vec<f32>> {
    if weights.len() != PLANE || weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(ModelError::Invalid(format!(
            "a slice basis needs {PLANE} positive cell weights, got {}",
            weights.len()
        )));
    }
    let scale: Vec<f32> = weights.iter().map(|w| w.sqrt()).collect();
    if layouts.is_empty() || m == 0 || m + OVERSAMPLING > PLANE {
        return Err(ModelError::Invalid(format!(
            "a slice basis of {m} directions from {} BRDFs",
            layouts.len()
        )));
    }
    if let Some(i) = layouts.iter().position(|l| l.len() != LAYOUT_VALUES) {
        return Err(ModelError::Invalid(format!(
            "layout {i} does not have {LAYOUT_VALUES} values"
        )));
    }
    let width = m + OVERSAMPLING;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x511c_eba5_15_u64);
    let start = DMatrix::<f64>::from_fn(PLANE, width, |_, _| rng.random_range(-1.0..1.0));
    let mut q = orthonormal(start);
    for _ in 1..PASSES {
        q = orthonormal(second_moment_times(layouts, &scale, &q, device)?);
    }
    // Rayleigh-Ritz on span(q): the eigenvectors of q^T C q, largest first.
    let cq = second_moment_times(layouts, &scale, &q, device)?;
    let small = q.transpose() * &cq;
    let small = (&small + small.transpose()) * 0.5;
    let eig = nalgebra::SymmetricEigen::try_new(small, 1e-14, 10_000).ok_or_else(|| {
        ModelError::Invalid("the slice basis' eigendecomposition did not converge".into())
    })?;
    let mut order: Vec<usize> = (0..width).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let mut rows = vec![0f32; m * PLANE];
    for (j, &e) in order.iter().take(m).enumerate() {
        let direction = &q * eig.eigenvectors.column(e);
        let row = rows[j * PLANE..(j + 1) * PLANE].iter_mut();
        for ((r, v), s) in row.zip(direction.iter()).zip(&scale) {
            *r = (*v / f64::from(*s)) as f32;
        }
    }
    Ok(rows)
}

/// The analysis matrix of the basis rows `basis` (`m x 8100`, row-major, the synthesis
/// directions of [`fit_slice_basis`]) under the cell weights `weights`: `(w S)^T`
/// (`[8100, m]`) on `device`, whose product with an image is its coefficients.
pub fn basis_t(basis: &[f32], weights: &[f32], device: &Device) -> Tensor<2> {
    let m = basis.len() / PLANE;
    let values: Vec<f32> = basis.iter().zip(weights.iter().cycle()).map(|(b, w)| b * w).collect();
    Tensor::<2>::from_data(TensorData::new(values, [m, PLANE]), device).transpose()
}

/// The coefficients of each of `layouts` in the basis (`basis_t` from [`basis_t`], with the
/// cell weights `weights`): 540 x m values, row-major (image-major, as the layout), and the
/// weighted squared distance of the layout to the span; one product for all of them.
pub fn project(
    layouts: &[&[f32]],
    basis_t: &Tensor<2>,
    weights: &[f32],
) -> Result<Vec<(Vec<f32>, f64)>> {
    let x = images(layouts, &basis_t.device());
    let out = read(x.matmul(basis_t.clone()))?; // [540 n, m]
    let len = out.len() / layouts.len().max(1);
    Ok(layouts
        .iter()
        .zip(out.chunks(len.max(1)))
        .map(|(layout, a)| {
            let total: f64 = layout
                .iter()
                .zip(weights.iter().cycle())
                .map(|(&v, &w)| f64::from(w) * f64::from(v) * f64::from(v))
                .sum();
            let inside: f64 = a.iter().map(|&v| f64::from(v) * f64::from(v)).sum();
            (a.to_vec(), (total - inside).max(0.0))
        })
        .collect())
}

/// The linear path of the network: the mean of the coefficient vectors and their `k` leading
/// principal directions (`k` rows of the vectors' length, orthonormal; zero past the rank).
#[derive(Clone, Debug)]
pub struct Components {
    /// The per-value mean of the vectors.
    pub mean: Vec<f32>,
    /// `k` rows, row-major.
    pub rows: Vec<f32>,
}

/// The mean and `k` leading principal directions of `vectors` (all of one length).
pub fn fit_components(vectors: &[Vec<f32>], k: usize) -> Result<Components> {
    fit_weighted_components(vectors, &vec![1.0; vectors.len()], k)
}

/// The weighted mean and `k` leading principal directions of `vectors`, vector i counted
/// `weights[i]` times (positive weights): the principal directions of the centred vectors
/// scaled by `sqrt(weights[i])`.
pub fn fit_weighted_components(
    vectors: &[Vec<f32>],
    weights: &[f64],
    k: usize,
) -> Result<Components> {
    let n = vectors.len();
    let len = vectors.first().map_or(0, Vec::len);
    if n == 0 || k == 0 || vectors.iter().any(|v| v.len() != len) {
        return Err(ModelError::Invalid(format!(
            "principal components (k = {k}) of {n} coefficient vectors of unequal or no length"
        )));
    }
    if weights.len() != n || weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(ModelError::Invalid(format!(
            "principal components of {n} vectors need {n} positive weights ({} given)",
            weights.len()
        )));
    }
    let mut mean = vec![0f64; len];
    for (v, &w) in vectors.iter().zip(weights) {
        for (m, &x) in mean.iter_mut().zip(v) {
            *m += w * f64::from(x);
        }
    }
    let total: f64 = weights.iter().sum();
    let mean: Vec<f32> = mean.iter().map(|&m| (m / total) as f32).collect();
    let scales: Vec<f64> = weights.iter().map(|w| w.sqrt()).collect();
    const BLOCK: usize = 4096;
    let blocks = len.div_ceil(BLOCK);
    let range = |b: usize| b * BLOCK..((b + 1) * BLOCK).min(len);
    let centred = |b: usize| {
        let r = range(b);
        DMatrix::<f64>::from_fn(n, r.len(), |i, c| {
            scales[i] * (f64::from(vectors[i][r.start + c]) - f64::from(mean[r.start + c]))
        })
    };
    let gram = ordered_block_sum(blocks, n, |b| {
        let x = centred(b);
        &x * x.transpose()
    });
    let pairs = leading_eigenpairs(gram, k)?;
    let wt = pairs.whitening().transpose();
    let parts: Vec<DMatrix<f64>> = (0..blocks).into_par_iter().map(|b| &wt * centred(b)).collect();
    let mut rows = vec![0f32; k * len];
    for (b, part) in parts.iter().enumerate() {
        let start = b * BLOCK;
        for j in 0..k {
            for c in 0..part.ncols() {
                rows[j * len + start + c] = part[(j, c)] as f32;
            }
        }
    }
    Ok(Components { mean, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Layouts whose every image is a mix of two fixed images.
    fn layouts() -> Vec<Vec<f32>> {
        let a: Vec<f32> = (0..PLANE).map(|i| ((i % 7) as f32 - 3.0) / 3.0).collect();
        let b: Vec<f32> = (0..PLANE).map(|i| ((i % 13) as f32) / 13.0).collect();
        (0..3)
            .map(|n| {
                let mut out = vec![0f32; LAYOUT_VALUES];
                for (image, chunk) in out.chunks_mut(PLANE).enumerate() {
                    let (p, q) = (((image + n) % 5) as f32, ((image * 3 + n) % 4) as f32 - 1.5);
                    for (i, v) in chunk.iter_mut().enumerate() {
                        *v = p * a[i] + q * b[i];
                    }
                }
                out
            })
            .collect()
    }

    #[test]
    fn the_slice_basis_spans_rank_two_images_and_is_orthonormal() {
        let data = layouts();
        let refs: Vec<&[f32]> = data.iter().map(Vec::as_slice).collect();
        let device = crate::device::DeviceKind::default_kind().unwrap().device().unwrap();
        let ones = pixel_weights(0.0);
        let basis = fit_slice_basis(&refs, 3, &ones, 7, &device).unwrap();
        assert_eq!(basis, fit_slice_basis(&refs, 3, &ones, 7, &device).unwrap(), "deterministic");
        let row = |j: usize| &basis[j * PLANE..(j + 1) * PLANE];
        let dot =
            |x: &[f32], y: &[f32]| x.iter().zip(y).map(|(a, b)| f64::from(a * b)).sum::<f64>();
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot(row(i), row(j)) - want).abs() < 1e-4, "{i} {j}");
            }
        }
        let bt = basis_t(&basis, &ones, &device);
        let projected = project(&refs, &bt, &ones).unwrap();
        assert_eq!(projected.len(), 3);
        for (layout, (a, residual)) in data.iter().zip(&projected) {
            assert_eq!(a.len(), 540 * 3);
            let total: f64 = layout.iter().map(|&v| f64::from(v * v)).sum();
            // The coefficients are f32 products over 8,100 values and the residual a difference
            // of two squared norms: rounding leaves up to ~sqrt(8100) * 2^-24 = 5e-6 of the
            // total; a missing direction leaves a sizeable fraction of it.
            assert!(*residual < 2e-5 * total, "{residual} of {total}");
        }
        assert!(fit_slice_basis(&[], 3, &ones, 0, &device).is_err());
        assert!(fit_slice_basis(&refs, 3, &ones[1..], 0, &device).is_err());
    }

    #[test]
    fn a_weighted_basis_fits_the_weighted_cells_better_and_its_coefficients_carry_the_weights() {
        // Images of rank 3: a shape over every cell, a larger one zero at theta_h bin 0 and a
        // spike on bin 0 alone, fitted by 2 directions. Unweighted the spike (few cells) is
        // dropped; with bin 0 weighted the spike is kept and the second shape dropped.
        let row0 = |i: usize| i / SIDE == 0;
        let smooth: Vec<f32> = (0..PLANE).map(|i| ((i * 3) % 17) as f32 / 17.0 + 1.0).collect();
        let rest: Vec<f32> = (0..PLANE)
            .map(|i| if row0(i) { 0.0 } else { ((i * 5) % 13) as f32 / 13.0 - 0.5 })
            .collect();
        let spike: Vec<f32> =
            (0..PLANE).map(|i| if row0(i) { 0.3 * (i % 2) as f32 } else { 0.0 }).collect();
        let layout = |n: usize| -> Vec<f32> {
            let mut out = vec![0f32; LAYOUT_VALUES];
            for (image, chunk) in out.chunks_mut(PLANE).enumerate() {
                let c = [(image + n) % 3, (image * 5 + n) % 4, (image + 2 * n) % 5];
                for (i, v) in chunk.iter_mut().enumerate() {
                    *v = c[0] as f32 * smooth[i] + c[1] as f32 * rest[i] + c[2] as f32 * spike[i];
                }
            }
            out
        };
        let data: Vec<Vec<f32>> = (0..3).map(layout).collect();
        let refs: Vec<&[f32]> = data.iter().map(Vec::as_slice).collect();
        let device = crate::device::DeviceKind::default_kind().unwrap().device().unwrap();
        // The error at theta_h bin 0 of the projections (synthesis S^T of the coefficients).
        let centre_error = |weights: &[f32]| -> f64 {
            let basis = fit_slice_basis(&refs, 2, weights, 7, &device).unwrap();
            let projected = project(&refs, &basis_t(&basis, weights, &device), weights).unwrap();
            let mut error = 0f64;
            for (layout, (a, residual)) in data.iter().zip(&projected) {
                let (mut weighted, mut total) = (0f64, 0f64);
                for (image, x) in layout.chunks(PLANE).enumerate() {
                    for p in 0..PLANE {
                        let y: f32 = (0..2).map(|j| a[image * 2 + j] * basis[j * PLANE + p]).sum();
                        let d = f64::from(x[p] - y);
                        weighted += f64::from(weights[p]) * d * d;
                        total += f64::from(weights[p]) * f64::from(x[p]) * f64::from(x[p]);
                        if p / SIDE == 0 {
                            error += d * d;
                        }
                    }
                }
                // The residual of `project` is the weighted squared distance to the span, a
                // difference of two f32 sums' squares: exact up to ~1e-6 of the weighted total.
                assert!((residual - weighted).abs() <= 1e-5 * total, "{residual} vs {weighted}");
            }
            error
        };
        let centre: Vec<f32> = (0..PLANE).map(|i| if row0(i) { 1e4 } else { 1.0 }).collect();
        let (plain, weighted) = (centre_error(&pixel_weights(0.0)), centre_error(&centre));
        assert!(plain > 1.0, "unweighted, the spike is dropped: centre error {plain}");
        assert!(weighted < 0.1 * plain, "centre error {weighted} weighted vs {plain}");
        assert_eq!(pixel_weights(3.0)[0], 4.0);
        assert_eq!(pixel_weights(3.0)[SIDE * 2 + 5], 2.0);
    }

    #[test]
    fn components_reproduce_rank_one_vectors() {
        let d: Vec<f32> = (0..10).map(|i| i as f32 - 4.0).collect();
        let vectors: Vec<Vec<f32>> =
            [1.0f32, -2.0, 0.5].iter().map(|&t| d.iter().map(|&x| 1.0 + t * x).collect()).collect();
        let c = fit_components(&vectors, 2).unwrap();
        let norm: f32 = c.rows[..10].iter().map(|v| v * v).sum();
        assert!((norm - 1.0).abs() < 1e-5);
        assert!(c.rows[10..].iter().all(|&v| v == 0.0), "rank one: the second row is zero");
        assert!((c.mean[0] - (1.0 - 4.0 * (-0.5 / 3.0))).abs() < 1e-5);
        assert!(fit_components(&[], 1).is_err());
    }

    #[test]
    fn a_weight_of_two_counts_a_vector_twice() {
        let vectors: Vec<Vec<f32>> = (0..4)
            .map(|i| (0..6).map(|c| ((i * 7 + c * 3) % 5) as f32 - (i as f32) * 0.3).collect())
            .collect();
        let weighted = fit_weighted_components(&vectors, &[1.0, 2.0, 1.0, 1.0], 3).unwrap();
        let mut repeated = vectors.clone();
        repeated.push(vectors[1].clone());
        let plain = fit_components(&repeated, 3).unwrap();
        for (a, b) in weighted.mean.iter().zip(&plain.mean) {
            assert!((a - b).abs() < 1e-5, "mean {a} vs {b}");
        }
        // The same directions, up to sign.
        for j in 0..3 {
            let (a, b) = (&weighted.rows[j * 6..(j + 1) * 6], &plain.rows[j * 6..(j + 1) * 6]);
            let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-4, "direction {j}: |dot| {dot}");
        }
        assert!(fit_weighted_components(&vectors, &[1.0, 0.0, 1.0, 1.0], 3).is_err());
        assert!(fit_weighted_components(&vectors, &[1.0; 3], 3).is_err());
    }
}

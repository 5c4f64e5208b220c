//! The principal directions of a training set in the eq. (1) mapped space, centred on the
//! training mean and masked to valid cells (the space the loss of eq. (4) is measured in): the
//! basis of the `cpu` preset's spectral path ([`crate::spectral`]).
//!
//! The Gram route of PCA shared with `deepbrdf-eval`'s baselines ([`deepbrdf_data::gram_pca`]):
//! G = R R^T over the n centred rows R in f64 (summed block by block in a fixed order, so the
//! fit is deterministic), its eigenvectors V and values s^2 (eigenvalues at the core's floor
//! left out, their row of U zero), U = diag(1/s) V^T R. The coordinates of training row i are
//! then `c_ij = s_j V_ij` and its squared distance to the span is `G_ii - |c_i|^2`.

use crate::autoencoder::INPUT_VALUES;
use crate::error::{ModelError, Result};
use crate::training_set::TrainingSet;
use deepbrdf_data::gram_pca::{leading_eigenpairs, ordered_block_sum};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Values per block of the Gram accumulation.
const BLOCK: usize = 1 << 15;

/// Rows `(x_i - offset) * mask_i` of `data` over `range`, as an n x len matrix in f64.
fn centred_block(
    data: &TrainingSet,
    offset: &[f32],
    range: std::ops::Range<usize>,
) -> DMatrix<f64> {
    let n = data.len();
    let len = range.len();
    DMatrix::from_fn(n, len, |i, c| {
        let v = range.start + c;
        f64::from((data.input(i)[v] - offset[v]) * data.mask(i)[v])
    })
}

/// A fitted basis and the training set's coordinates in it.
#[derive(Clone, Debug)]
pub struct PrincipalFit {
    /// `k` rows of [`INPUT_VALUES`] values (row-major, orthonormal; rows past the data's rank
    /// are zero).
    pub basis: Vec<f32>,
    /// `n` rows of `k` coordinates, `U (x_i - offset) * mask_i`.
    pub coefficients: Vec<Vec<f32>>,
    /// Squared distance of each centred row to the basis' span.
    pub residuals: Vec<f64>,
}

/// The `k` leading principal directions of `data` centred on `offset`.
pub fn fit_basis(data: &TrainingSet, offset: &[f32], k: usize) -> Result<PrincipalFit> {
    let n = data.len();
    if n == 0 || k == 0 {
        return Err(ModelError::Invalid(format!("a linear path of k = {k} from {n} BRDFs")));
    }
    if offset.len() != INPUT_VALUES {
        return Err(ModelError::Invalid(format!(
            "an offset has {INPUT_VALUES} values, got {}",
            offset.len()
        )));
    }
    let blocks = INPUT_VALUES.div_ceil(BLOCK);
    let range = |b: usize| b * BLOCK..((b + 1) * BLOCK).min(INPUT_VALUES);
    let gram = ordered_block_sum(blocks, n, |b| {
        let x = centred_block(data, offset, range(b));
        &x * x.transpose()
    });
    let gram_diagonal: Vec<f64> = (0..n).map(|i| gram[(i, i)]).collect();
    let pairs = leading_eigenpairs(gram, k)?;
    // W = V_k diag(1/s) (n x k), zero columns past the rank; coordinates s_j V_ij.
    let mut w = DMatrix::<f64>::zeros(n, k);
    let mut coefficients = vec![vec![0f32; k]; n];
    for (j, &s) in pairs.sigmas.iter().enumerate() {
        if s > 0.0 {
            for i in 0..n {
                w[(i, j)] = pairs.vectors[(i, j)] / s;
                coefficients[i][j] = (pairs.vectors[(i, j)] * s) as f32;
            }
        }
    }
    let residuals = (0..n)
        .map(|i| {
            let c2: f64 = coefficients[i].iter().map(|&c| f64::from(c).powi(2)).sum();
            (gram_diagonal[i] - c2).max(0.0)
        })
        .collect();
    let wt = w.transpose();
    // U = W^T R, block by block (k x block), a few blocks at a time in parallel: the f64
    // products of all blocks at once would be twice the f32 basis (3.4 GB for the `cpu`
    // preset's 96 directions).
    let mut basis = vec![0f32; k * INPUT_VALUES];
    let group = rayon::current_num_threads().max(1);
    for first in (0..blocks).step_by(group) {
        let parts: Vec<DMatrix<f64>> = (first..(first + group).min(blocks))
            .into_par_iter()
            .map(|b| &wt * centred_block(data, offset, range(b)))
            .collect();
        for (b, part) in (first..).zip(&parts) {
            let start = b * BLOCK;
            for j in 0..k {
                let row =
                    &mut basis[j * INPUT_VALUES + start..j * INPUT_VALUES + start + part.ncols()];
                for (c, v) in row.iter_mut().enumerate() {
                    *v = part[(j, c)] as f32;
                }
            }
        }
    }
    Ok(PrincipalFit { basis, coefficients, residuals })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three BRDFs spanning two directions around their mean.
    fn set() -> (TrainingSet, Vec<f32>) {
        let a: Vec<f32> = (0..INPUT_VALUES).map(|i| ((i % 7) as f32 - 3.0) / 3.0).collect();
        let b: Vec<f32> = (0..INPUT_VALUES).map(|i| ((i % 5) as f32 - 2.0) / 2.0).collect();
        let mask: Vec<f32> =
            (0..INPUT_VALUES).map(|i| if i % 11 == 0 { 0.0 } else { 1.0 }).collect();
        let mix = |p: f32, q: f32| -> Vec<f32> {
            (0..INPUT_VALUES).map(|i| (1.0 + p * a[i] + q * b[i]) * mask[i]).collect()
        };
        let inputs = vec![mix(1.0, 0.0), mix(-0.5, 1.0), mix(-0.5, -1.0)];
        let names = (0..3).map(|i| format!("m{i}")).collect();
        let set =
            TrainingSet::from_layouts("synthetic", names, inputs, vec![mask.clone(); 3]).unwrap();
        let offset = set.mean();
        (set, offset)
    }

    #[test]
    fn the_basis_is_orthonormal_and_reconstructs_the_training_set() {
        let (set, offset) = set();
        let fit = fit_basis(&set, &offset, 3).unwrap();
        let basis = fit.basis;
        let row = |j: usize| &basis[j * INPUT_VALUES..(j + 1) * INPUT_VALUES];
        let dot =
            |x: &[f32], y: &[f32]| x.iter().zip(y).map(|(a, b)| f64::from(a * b)).sum::<f64>();
        assert!((dot(row(0), row(0)) - 1.0).abs() < 1e-4);
        assert!((dot(row(1), row(1)) - 1.0).abs() < 1e-4);
        assert!(dot(row(0), row(1)).abs() < 1e-4);
        // Rank 2: the third direction is left out.
        assert_eq!(dot(row(2), row(2)), 0.0);
        for i in 0..3 {
            let r: Vec<f32> =
                (0..INPUT_VALUES).map(|v| (set.input(i)[v] - offset[v]) * set.mask(i)[v]).collect();
            let z: Vec<f64> = (0..2).map(|j| dot(row(j), &r)).collect();
            let err = (0..INPUT_VALUES)
                .map(|v| {
                    let back = z[0] * f64::from(row(0)[v]) + z[1] * f64::from(row(1)[v]);
                    (back - f64::from(r[v])).powi(2)
                })
                .sum::<f64>();
            assert!(err < 1e-6 * dot(&r, &r), "BRDF {i}: {err}");
            // The returned coordinates are these projections; nothing is left outside the span.
            for j in 0..2 {
                assert!(
                    (f64::from(fit.coefficients[i][j]) - z[j]).abs() < 1e-3 * dot(&r, &r).sqrt()
                );
            }
            assert!(fit.residuals[i] < 1e-6 * dot(&r, &r), "{}", fit.residuals[i]);
        }
        assert!(fit_basis(&set, &offset[1..], 2).is_err());
    }
}

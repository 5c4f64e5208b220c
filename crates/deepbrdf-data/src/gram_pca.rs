//! The Gram route of PCA (eq. 5 of Hu et al. 2020, `A - mu = U Sigma V^T`), shared by the PCA and
//! IPCA baselines (`deepbrdf-eval`) and the slice network's basis (`deepbrdf-model`).
//!
//! With n centred rows of a large dimension d (4,374,000 for a MERL table) the `d x d` covariance
//! is never formed: the `n x n` Gram matrix `G = (A - mu)(A - mu)^T` is accumulated in f64 over
//! column blocks ([`ordered_block_sum`]: blocks computed in parallel, added in block order, so the
//! result is the same bit for bit whatever the thread count), and its eigenpairs
//! `G u_j = lambda_j u_j` ([`leading_eigenpairs`]) give the singular values
//! `sigma_j = sqrt(lambda_j)` and the principal directions `v_j = (A - mu)^T u_j / sigma_j`.

use crate::error::{DataError, Result};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Eigenvalues of the Gram matrix at or below this fraction of the largest are treated as zero:
/// their directions are numerical noise (data of rank r < n leaves n - r of them at round-off
/// level), so the corresponding directions are left out instead of amplifying noise by
/// `1/sigma`.
pub const RELATIVE_EIGEN_FLOOR: f64 = 1e-12;

/// `sum_b part(b)` over `b in 0..blocks` of `n x n` matrices: the parts are computed in parallel
/// and added in block order, starting from zero, so the sum does not depend on the thread count.
pub fn ordered_block_sum(
    blocks: usize,
    n: usize,
    part: impl Fn(usize) -> DMatrix<f64> + Sync + Send,
) -> DMatrix<f64> {
    let parts: Vec<DMatrix<f64>> = (0..blocks).into_par_iter().map(part).collect();
    parts.into_iter().fold(DMatrix::<f64>::zeros(n, n), |a, b| a + b)
}

/// The `k` leading eigenpairs of a Gram matrix, largest first.
#[derive(Clone, Debug)]
pub struct LeadingPairs {
    /// `sigma_j = sqrt(lambda_j)`, 0 for an eigenvalue at or below the floor (or for `j` past
    /// `n`).
    pub sigmas: Vec<f64>,
    /// `n x k`: column j is the unit eigenvector u_j, or zero where `sigmas[j]` is 0.
    pub vectors: DMatrix<f64>,
}

impl LeadingPairs {
    /// `W = U_k diag(1 / sigma)` (`n x k`), a zero column where `sigma_j` is 0: the weights
    /// of the n centred rows in each principal direction, `v_j = (A - mu)^T W[:, j]`.
    pub fn whitening(&self) -> DMatrix<f64> {
        let mut w = DMatrix::<f64>::zeros(self.vectors.nrows(), self.sigmas.len());
        for (j, &sigma) in self.sigmas.iter().enumerate() {
            if sigma > 0.0 {
                w.set_column(j, &(self.vectors.column(j) / sigma));
            }
        }
        w
    }
}

/// The `k` leading eigenpairs of `gram` (symmetrised first), eigenvalues at or below
/// [`RELATIVE_EIGEN_FLOOR`] times the largest (or not positive) dropped.
pub fn leading_eigenpairs(gram: DMatrix<f64>, k: usize) -> Result<LeadingPairs> {
    let n = gram.nrows();
    if n == 0 || gram.ncols() != n {
        return Err(DataError::Invalid(format!(
            "a Gram matrix must be square and non-empty, got {} x {}",
            gram.nrows(),
            gram.ncols()
        )));
    }
    let gram = (&gram + gram.transpose()) * 0.5;
    let eig = nalgebra::SymmetricEigen::try_new(gram, 1e-14, 10_000).ok_or_else(|| {
        DataError::Invalid("the Gram matrix eigendecomposition did not converge".into())
    })?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let floor = eig.eigenvalues[order[0]].max(0.0) * RELATIVE_EIGEN_FLOOR;
    let mut sigmas = vec![0.0; k];
    let mut vectors = DMatrix::<f64>::zeros(n, k);
    for (j, &e) in order.iter().take(k).enumerate() {
        let lambda = eig.eigenvalues[e];
        if lambda > floor && lambda > 0.0 {
            sigmas[j] = lambda.sqrt();
            vectors.set_column(j, &eig.eigenvectors.column(e));
        }
    }
    Ok(LeadingPairs { sigmas, vectors })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_sum_is_in_block_order_and_independent_of_threads() {
        // Parts whose sum depends on the order of addition in f64.
        let part = |b: usize| DMatrix::from_element(2, 2, if b % 2 == 0 { 1e16 } else { 1.0 });
        let sequential = (0..7).map(part).fold(DMatrix::zeros(2, 2), |a, b| a + b);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
        let four = rayon::ThreadPoolBuilder::new().num_threads(4).build().expect("pool");
        assert_eq!(one.install(|| ordered_block_sum(7, 2, part)), sequential);
        assert_eq!(four.install(|| ordered_block_sum(7, 2, part)), sequential);
    }

    #[test]
    fn leading_pairs_are_sorted_and_drop_the_null_space() {
        // G = diag(1, 9, 0, 4) in a rotated frame: eigenvalues 9, 4, 1, 0.
        let (c, s) = (0.6f64, 0.8f64);
        let r = DMatrix::from_row_slice(
            4,
            4,
            &[c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c],
        );
        let d = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 9.0, 0.0, 4.0]));
        let gram = &r * d * r.transpose();
        let pairs = leading_eigenpairs(gram.clone(), 4).expect("eigen");
        let want = [3.0, 2.0, 1.0, 0.0];
        for (got, want) in pairs.sigmas.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{:?}", pairs.sigmas);
        }
        for j in 0..3 {
            let u = pairs.vectors.column(j);
            let gu = &gram * u;
            assert!((gu - u * pairs.sigmas[j].powi(2)).norm() < 1e-12, "column {j}");
        }
        // The whitening divides each vector by its sigma and keeps the dropped one at zero.
        let w = pairs.whitening();
        for j in 0..3 {
            assert!((w.column(j) * pairs.sigmas[j] - pairs.vectors.column(j)).norm() < 1e-12);
        }
        assert_eq!(w.column(3).norm(), 0.0);
        assert_eq!(pairs.vectors.column(3).norm(), 0.0, "the null direction is dropped");
        assert!(leading_eigenpairs(DMatrix::zeros(2, 3), 1).is_err());
    }
}

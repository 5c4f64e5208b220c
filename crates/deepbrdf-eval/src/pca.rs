//! Principal component analysis of BRDFs, eq. (5) of Hu et al. 2020 (§4):
//! `A - mu = U Sigma V^T`, truncated to the first k terms, with one BRDF per row of `A`.
//!
//! [`LinearBasis`] is the linear algebra on plain rows of any length (so it can be tested on
//! small synthetic data); the paper's "traditional PCA" on MERL tables: the natural
//! logarithm of the reflectance ([`LOG_EPSILON`] added), all three channels in one row, over the
//! valid cells, is this basis fitted by the baselines' `BaselineMethod::pca`.
//!
//! The fit never forms the `d x d` covariance (d = 4,374,000 for a MERL table): it takes the
//! Gram route of [`deepbrdf_data::gram_pca`] (the `n x n` Gram matrix in f64 over column blocks
//! added in a fixed order, its eigenpairs giving `sigma_j` and the principal directions
//! `v_j = (A - mu)^T u_j / sigma_j`, the columns of V in eq. 5). Components are stored as f32.
//! Every sum has a fixed order, so a fit and an encoding are the same bits for any thread count.

use crate::error::{EvalError, Result};
use deepbrdf_data::gram_pca::{leading_eigenpairs, ordered_block_sum};
use deepbrdf_data::Progress;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Columns per block of the Gram and projection passes (a block of 100 rows is 3.2 MB in f64).
const BLOCK: usize = 4096;

/// The epsilon of traditional PCA's logarithm: rows hold `ln(rho + LOG_EPSILON)`. The paper only
/// says "the natural logarithm"; MERL tables contain zeros, so a small offset is needed, and we
/// take the same 0.001 as the paper's eq. (1).
pub const LOG_EPSILON: f64 = 1e-3;

/// Traditional PCA's forward mapping of a reflectance: `ln(rho + LOG_EPSILON)` (a negative
/// `rho`, a remainder, floored at `-LOG_EPSILON / 2` so the logarithm stays finite).
#[inline]
pub fn log_map(rho: f64) -> f64 {
    (rho + LOG_EPSILON).max(0.5 * LOG_EPSILON).ln()
}

/// Inverse of [`log_map`]: `exp(y) - LOG_EPSILON` (may be negative for a truncated basis).
#[inline]
pub fn log_unmap(y: f64) -> f64 {
    y.exp() - LOG_EPSILON
}

/// A fitted linear basis: the mean row and the first `k` principal directions.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearBasis {
    dim: usize,
    k: usize,
    mean: Vec<f32>,
    /// V of eq. (5), `dim x k`, row-major (row d holds the k component values of coordinate d).
    components: Vec<f32>,
    /// sigma_1 >= sigma_2 >= ... of eq. (5), `k` of them (0 for dropped directions).
    singular_values: Vec<f64>,
}

impl LinearBasis {
    /// Fits eq. (5) to `rows` (n rows of equal length) and keeps `k` components, `k <= n - 1`
    /// (the rank of n centred rows is at most n - 1).
    pub fn fit(rows: &[&[f32]], k: usize, progress: &dyn Progress) -> Result<Self> {
        let n = rows.len();
        if n < 2 {
            return Err(EvalError::Invalid(format!("PCA needs at least 2 rows, got {n}")));
        }
        let dim = rows[0].len();
        if let Some(bad) = rows.iter().position(|r| r.len() != dim) {
            return Err(EvalError::Invalid(format!(
                "PCA rows differ in length: row 0 has {dim}, row {bad} has {}",
                rows[bad].len()
            )));
        }
        if k == 0 || k > n - 1 {
            return Err(EvalError::Invalid(format!(
                "k = {k} components requested from {n} rows: k must be in 1..={}",
                n - 1
            )));
        }
        if dim == 0 {
            return Err(EvalError::Invalid("PCA rows are empty".into()));
        }
        let blocks = dim.div_ceil(BLOCK);
        progress.start(2 * blocks as u64, "PCA fit");

        // Mean of each column, f64 accumulation, stored as f32 (the stored mean is what encode
        // and decode use, so the centring below uses exactly the stored value).
        let mut mean = vec![0f32; dim];
        mean.par_chunks_mut(BLOCK).enumerate().for_each(|(b, chunk)| {
            let start = b * BLOCK;
            for (c, m) in chunk.iter_mut().enumerate() {
                let s: f64 = rows.iter().map(|r| f64::from(r[start + c])).sum();
                *m = (s / n as f64) as f32;
            }
        });

        // G = sum over blocks of Xb^T Xb, Xb the centred block (block columns x n,
        // column-major), added in block order (the same bits for any thread count).
        let gram = ordered_block_sum(blocks, n, |b| {
            let xb = centred_block(rows, &mean, b);
            let g = xb.transpose() * &xb;
            progress.advance(1);
            g
        });
        let pairs = leading_eigenpairs(gram, k)?;

        // W = U_k diag(1/sigma) (n x k); a zero column for eigenvalues at the noise floor.
        let w = pairs.whitening();
        let singular_values = pairs.sigmas;

        // V = (A - mu)^T W, block by block: Vb = Xb W (block columns x k).
        let mut components = vec![0f32; dim * k];
        components.par_chunks_mut(BLOCK * k).enumerate().for_each(|(b, out)| {
            let xb = centred_block(rows, &mean, b);
            let vb = &xb * &w;
            let cols = xb.nrows();
            for c in 0..cols {
                for j in 0..k {
                    out[c * k + j] = vb[(c, j)] as f32;
                }
            }
            progress.advance(1);
        });
        progress.finish();
        Ok(Self { dim, k, mean, components, singular_values })
    }

    /// Assembles a basis from stored parts (an artifact); checks the lengths agree.
    pub fn from_parts(
        dim: usize,
        k: usize,
        mean: Vec<f32>,
        components: Vec<f32>,
        singular_values: Vec<f64>,
    ) -> Result<Self> {
        if mean.len() != dim || components.len() != dim * k || singular_values.len() != k {
            return Err(EvalError::Invalid(format!(
                "inconsistent basis parts: dim {dim}, k {k}, mean {}, components {}, sigmas {}",
                mean.len(),
                components.len(),
                singular_values.len()
            )));
        }
        Ok(Self { dim, k, mean, components, singular_values })
    }

    /// Length of a row.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of stored components.
    pub fn k(&self) -> usize {
        self.k
    }

    /// The mean row (mu of eq. 5).
    pub fn mean(&self) -> &[f32] {
        &self.mean
    }

    /// The components, `dim x k` row-major.
    pub fn components(&self) -> &[f32] {
        &self.components
    }

    /// The singular values sigma_j of eq. (5).
    pub fn singular_values(&self) -> &[f64] {
        &self.singular_values
    }

    /// Coefficients of `row` on the first `k` components: `c_j = v_j . (row - mu)` (f64 sums).
    pub fn encode(&self, row: &[f32], k: usize) -> Result<Vec<f32>> {
        if row.len() != self.dim {
            return Err(EvalError::Invalid(format!(
                "row of length {} given to a basis of dimension {}",
                row.len(),
                self.dim
            )));
        }
        self.check_k(k)?;
        let kk = self.k;
        // Per-block partial sums in parallel, added in block order (thread-count independent).
        let parts: Vec<Vec<f64>> = row
            .par_chunks(BLOCK)
            .enumerate()
            .map(|(b, chunk)| {
                let start = b * BLOCK;
                let mut acc = vec![0f64; k];
                for (c, &x) in chunk.iter().enumerate() {
                    let d = start + c;
                    let centred = f64::from(x) - f64::from(self.mean[d]);
                    let v = &self.components[d * kk..d * kk + k];
                    for (a, &vj) in acc.iter_mut().zip(v) {
                        *a += centred * f64::from(vj);
                    }
                }
                acc
            })
            .collect();
        let mut sums = vec![0f64; k];
        for part in &parts {
            sums.iter_mut().zip(part).for_each(|(x, y)| *x += y);
        }
        Ok(sums.into_iter().map(|s| s as f32).collect())
    }

    /// The row `mu + sum_j c_j v_j` for coefficients `code` (its length is the k used).
    pub fn decode(&self, code: &[f32]) -> Result<Vec<f32>> {
        let k = code.len();
        self.check_k(k)?;
        let kk = self.k;
        let mut row = vec![0f32; self.dim];
        row.par_chunks_mut(BLOCK).enumerate().for_each(|(b, chunk)| {
            let start = b * BLOCK;
            for (c, out) in chunk.iter_mut().enumerate() {
                let d = start + c;
                let v = &self.components[d * kk..d * kk + k];
                let s: f64 =
                    v.iter().zip(code).map(|(&vj, &cj)| f64::from(vj) * f64::from(cj)).sum();
                *out = (f64::from(self.mean[d]) + s) as f32;
            }
        });
        Ok(row)
    }

    fn check_k(&self, k: usize) -> Result<()> {
        if k > self.k {
            return Err(EvalError::Invalid(format!(
                "{k} coefficients requested from a basis of {} components",
                self.k
            )));
        }
        Ok(())
    }
}

/// Block `b` of the centred rows as a (block columns x n) column-major f64 matrix: column i is
/// row i's slice minus the mean.
fn centred_block(rows: &[&[f32]], mean: &[f32], b: usize) -> DMatrix<f64> {
    let dim = mean.len();
    let start = b * BLOCK;
    let end = (start + BLOCK).min(dim);
    let cols = end - start;
    let mut data = Vec::with_capacity(cols * rows.len());
    for r in rows {
        data.extend(
            r[start..end].iter().zip(&mean[start..end]).map(|(&x, &m)| f64::from(x) - f64::from(m)),
        );
    }
    DMatrix::from_vec(cols, rows.len(), data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::Silent;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// n rows of length d with exact rank r around a non-zero mean: row = mu + sum_j a_ij b_j.
    fn low_rank(n: usize, d: usize, r: usize, seed: u64) -> Vec<Vec<f32>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mu: Vec<f32> = (0..d).map(|_| rng.random_range(-1.0..1.0)).collect();
        let basis: Vec<Vec<f32>> =
            (0..r).map(|_| (0..d).map(|_| rng.random_range(-1.0..1.0)).collect()).collect();
        (0..n)
            .map(|_| {
                let a: Vec<f32> = (0..r).map(|_| rng.random_range(-2.0..2.0)).collect();
                (0..d).map(|x| mu[x] + (0..r).map(|j| a[j] * basis[j][x]).sum::<f32>()).collect()
            })
            .collect()
    }

    fn refs(rows: &[Vec<f32>]) -> Vec<&[f32]> {
        rows.iter().map(|r| r.as_slice()).collect()
    }

    fn reconstruction_mse(basis: &LinearBasis, rows: &[Vec<f32>], k: usize) -> f64 {
        let mut s = 0.0;
        let mut count = 0usize;
        for r in rows {
            let back = basis.decode(&basis.encode(r, k).unwrap()).unwrap();
            s += r.iter().zip(&back).map(|(a, b)| f64::from(a - b).powi(2)).sum::<f64>();
            count += r.len();
        }
        s / count as f64
    }

    #[test]
    fn known_rank_is_reconstructed_exactly_for_k_at_least_rank() {
        // d spans several blocks so the blocked passes are exercised.
        let (n, d, r) = (12, 2 * BLOCK + 77, 3);
        let rows = low_rank(n, d, r, 1);
        let basis = LinearBasis::fit(&refs(&rows), n - 1, &Silent).unwrap();
        let scale =
            rows.iter().flatten().map(|x| f64::from(*x).powi(2)).sum::<f64>() / (n * d) as f64;
        for k in r..n {
            let mse = reconstruction_mse(&basis, &rows, k);
            assert!(mse < 1e-9 * scale, "k = {k}: mse {mse} (data scale {scale})");
        }
        // Below the rank the error is clearly non-zero.
        assert!(reconstruction_mse(&basis, &rows, r - 1) > 1e-3 * scale);
        // Directions beyond the rank are at the noise floor and dropped.
        assert!(
            basis.singular_values()[r..].iter().all(|&s| s == 0.0),
            "{:?}",
            basis.singular_values()
        );
    }

    #[test]
    fn in_sample_error_is_non_increasing_in_k_and_zero_at_n_minus_1() {
        let (n, d) = (9, 500);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let rows: Vec<Vec<f32>> =
            (0..n).map(|_| (0..d).map(|_| rng.random_range(0.0..1.0)).collect()).collect();
        let basis = LinearBasis::fit(&refs(&rows), n - 1, &Silent).unwrap();
        let errors: Vec<f64> = (0..n).map(|k| reconstruction_mse(&basis, &rows, k)).collect();
        for k in 1..n {
            assert!(errors[k] <= errors[k - 1] * (1.0 + 1e-6), "k = {k}: {errors:?}");
        }
        // n centred rows have rank n - 1: k = n - 1 reproduces them up to f32 round-off.
        assert!(errors[n - 1] < 1e-10, "{errors:?}");
        assert!(errors[0] > 1e-2, "{errors:?}");
    }

    #[test]
    fn gram_route_agrees_with_a_direct_svd() {
        // Independent computation: nalgebra's SVD of the centred n x d matrix (eq. 5 directly).
        let (n, d) = (7, 40);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let rows: Vec<Vec<f32>> =
            (0..n).map(|_| (0..d).map(|_| rng.random_range(-1.0..1.0)).collect()).collect();
        let k = 4;
        let basis = LinearBasis::fit(&refs(&rows), k, &Silent).unwrap();

        let mut a = DMatrix::<f64>::zeros(n, d);
        for (i, r) in rows.iter().enumerate() {
            for (x, &v) in r.iter().enumerate() {
                a[(i, x)] = f64::from(v);
            }
        }
        let mu = a.row_mean();
        for x in 0..d {
            assert!((mu[x] - f64::from(basis.mean()[x])).abs() < 1e-6);
        }
        for i in 0..n {
            for x in 0..d {
                a[(i, x)] -= mu[x];
            }
        }
        let svd = a.svd(false, true);
        let v_t = svd.v_t.unwrap();
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|&p, &q| svd.singular_values[q].total_cmp(&svd.singular_values[p]));
        for j in 0..k {
            let sigma = svd.singular_values[order[j]];
            assert!(
                (sigma - basis.singular_values()[j]).abs() < 1e-5 * sigma,
                "sigma_{j}: svd {sigma} gram {}",
                basis.singular_values()[j]
            );
            // Same direction up to sign.
            let dot: f64 =
                (0..d).map(|x| v_t[(order[j], x)] * f64::from(basis.components()[x * k + j])).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-5, "component {j}: |cos| = {}", dot.abs());
        }
    }

    #[test]
    fn bad_arguments_are_errors() {
        let rows = low_rank(4, 10, 2, 2);
        assert!(LinearBasis::fit(&refs(&rows), 4, &Silent).is_err());
        assert!(LinearBasis::fit(&refs(&rows), 0, &Silent).is_err());
        assert!(LinearBasis::fit(&refs(&rows[..1]), 1, &Silent).is_err());
        let short = [rows[0].as_slice(), &rows[1][..5]];
        assert!(LinearBasis::fit(&short, 1, &Silent).is_err());
        let basis = LinearBasis::fit(&refs(&rows), 3, &Silent).unwrap();
        assert!(basis.encode(&rows[0][..9], 2).is_err());
        assert!(basis.encode(&rows[0], 4).is_err());
        assert!(basis.decode(&[0.0; 4]).is_err());
    }
}

//! The plane of Fig. 5 (Hu et al. 2020, §3.3): a set of latent vectors projected onto their
//! first two principal components, so the manifold the autoencoder maps the materials to can be
//! looked at in two dimensions. The projection is eq. (5) on the latents ([`LinearBasis`]), with
//! the share of the latents' variance that the plane keeps.

use crate::error::{EvalError, Result};
use crate::pca::LinearBasis;
use deepbrdf_data::Silent;

/// Latents projected to their principal plane.
#[derive(Clone, Debug, PartialEq)]
pub struct LatentPlane {
    /// (PC 1, PC 2) of each latent, in the input's order.
    pub coords: Vec<[f64; 2]>,
    /// The share of the latents' total variance along each of the two axes:
    /// `sigma_j^2 / sum_i sigma_i^2` over every component of the latents.
    pub explained: [f64; 2],
}

impl LatentPlane {
    /// Projects `latents` (at least 3, all of one length of at least 2) onto their first two
    /// principal components.
    pub fn fit(latents: &[Vec<f32>]) -> Result<Self> {
        let n = latents.len();
        let dim = latents.first().map_or(0, Vec::len);
        if n < 3 || dim < 2 {
            return Err(EvalError::Invalid(format!(
                "a principal plane needs at least 3 latents of at least 2 values, got {n} of {dim}"
            )));
        }
        let rows: Vec<&[f32]> = latents.iter().map(Vec::as_slice).collect();
        // Every component the n centred rows can have (rank <= min(n - 1, dim)): the total
        // variance is the sum of all their squared singular values.
        let basis = LinearBasis::fit(&rows, (n - 1).min(dim), &Silent)?;
        let total: f64 = basis.singular_values().iter().map(|s| s * s).sum();
        if !(total > 0.0) {
            return Err(EvalError::Invalid(format!("the {n} latents are all the same")));
        }
        let sigma = basis.singular_values();
        let explained = [sigma[0] * sigma[0] / total, sigma[1] * sigma[1] / total];
        let coords = rows
            .iter()
            .map(|r| {
                let c = basis.encode(r, 2)?;
                Ok([f64::from(c[0]), f64::from(c[1])])
            })
            .collect::<Result<_>>()?;
        Ok(Self { coords, explained })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_on_a_plane_in_3d_keep_their_distances_and_all_the_variance() {
        // Points a*u + b*w in R^3 with u, w orthonormal: the principal plane is span(u, w), so
        // the projection keeps every pairwise distance and 100% of the variance, the larger
        // spread (a, from -2 to 2) on the first axis.
        let u = [0.6f32, 0.8, 0.0];
        let w = [0.0f32, 0.0, 1.0];
        let ab = [(-2.0f32, 0.1f32), (-1.0, -0.3), (0.5, 0.2), (2.0, 0.0), (0.5, -0.1)];
        let latents: Vec<Vec<f32>> =
            ab.iter().map(|&(a, b)| (0..3).map(|i| a * u[i] + b * w[i]).collect()).collect();
        let plane = LatentPlane::fit(&latents).unwrap();
        assert!((plane.explained[0] + plane.explained[1] - 1.0).abs() < 1e-9, "{plane:?}");
        assert!(plane.explained[0] > 0.9, "{plane:?}");
        for i in 0..ab.len() {
            for j in 0..ab.len() {
                let d_in = ((ab[i].0 - ab[j].0).powi(2) + (ab[i].1 - ab[j].1).powi(2)).sqrt();
                let (p, q) = (plane.coords[i], plane.coords[j]);
                let d_out = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                assert!((f64::from(d_in) - d_out).abs() < 1e-5, "{i} {j}: {d_in} vs {d_out}");
            }
        }
    }

    #[test]
    fn too_few_or_identical_latents_are_refused() {
        assert!(LatentPlane::fit(&[vec![1.0, 2.0], vec![0.0, 1.0]]).is_err());
        assert!(LatentPlane::fit(&[vec![1.0], vec![0.0], vec![2.0]]).is_err());
        assert!(LatentPlane::fit(&vec![vec![1.0, 2.0]; 4]).is_err());
    }
}

//! Sun et al. 2018's diffuse-specular separation as a baseline of the harness, the
//! comparison of Fig. 8 of Hu et al. 2020: T. Sun, H. W. Jensen, R. Ramamoorthi, "Connecting
//! Measured BRDFs to Analytic BRDFs by Data-Driven Diffuse-Specular Separation", ACM TOG 37(6)
//! 2018, §4.
//!
//! A BRDF is a Lambertian part `albedo / pi` per channel plus a specular part. Which albedo a
//! measured BRDF has is not measured; the separation picks, per BRDF, the albedo at which the
//! collection's specular parts explain it best: from the classical estimate (the table's
//! smallest value, [`lowest_albedos`]) it fits a PCA of the specular parts (in IPCA's mapped
//! space, [`crate::ipca`]) and searches each BRDF's albedo against it ([`SearchBasis`]), as
//! often as [`SeparationConfig::iterations`] says. The representation then holds PCA
//! coefficients of the albedo and of the specular part, separately: Fig. 8 gives the diffuse
//! part 1 dimension and the specular part 9 at k = 10, and [`SeparatedMethod`] runs at any k as
//! 1 + (k - 1). The authors publish no code; the choices the paper leaves open are
//! [`SeparationConfig`]'s, with their reasons.

mod basis;
mod edit;
mod search;

pub use basis::SeparatedBasis;
pub use edit::{fit_split, separated_attributes};
pub use search::{lowest_albedos, Sample, SearchBasis};

use crate::baseline::{max_k, SharedEncoding};
use crate::error::{EvalError, Result};
use crate::harness::{Codec, Method};
use deepbrdf_data::{MerlTable, Progress};
use std::sync::Arc;

/// The method's name in tables and plots.
pub const NAME: &str = "Sun2018";

/// The fewest training BRDFs the separation takes: two halves of two.
pub const MIN_TRAIN: usize = 4;

/// The settings of the separation.
#[derive(Clone, Debug, PartialEq)]
pub struct SeparationConfig {
    /// Coefficients of the diffuse part (PCA over the training albedos): Fig. 8's 1. With 3
    /// the albedo is kept as found, and a full set of specular components reproduces every
    /// training BRDF.
    pub diffuse_dims: usize,
    /// Specular components of the search's basis: 9, the specular dimensions of Fig. 8 (fewer
    /// for a small collection: a basis explains any of its own rows with one less component
    /// than it has rows, whatever the row's albedo).
    pub search_components: usize,
    /// Rounds of fit and search, at most (it stops when no albedo moves). One: the albedos
    /// of a Lambertian + GGX collection move away from the truth with every further round, as
    /// each round's basis learns the last round's errors (docs/results.md).
    pub iterations: usize,
    /// The search looks at every `stride`-th cell of the domain.
    pub stride: usize,
    /// eps of the specular part's mapping (IPCA's 0.001 by default): with the Lambertian part
    /// taken off, much of a specular part is near 0, where a small eps spends components on
    /// how its logarithm varies.
    pub specular_epsilon: f64,
}

impl Default for SeparationConfig {
    fn default() -> Self {
        Self {
            diffuse_dims: 1,
            search_components: 9,
            iterations: 1,
            stride: 32,
            specular_epsilon: crate::ipca::EPSILON,
        }
    }
}

impl SeparationConfig {
    /// Checks the settings against a training set of `n` BRDFs.
    pub fn check(&self, n: usize) -> Result<()> {
        if n < MIN_TRAIN {
            return Err(EvalError::Invalid(format!(
                "the separation needs at least {MIN_TRAIN} training BRDFs (each half separated \
                 against a basis of the other), got {n}"
            )));
        }
        if !(1..=3).contains(&self.diffuse_dims) {
            return Err(EvalError::Invalid(format!(
                "diffuse dimensions must be 1, 2 or 3, got {}",
                self.diffuse_dims
            )));
        }
        if !(self.specular_epsilon.is_finite() && self.specular_epsilon > 0.0) {
            return Err(EvalError::Invalid(format!(
                "the specular part's eps must be positive, got {}",
                self.specular_epsilon
            )));
        }
        if self.search_components == 0 || self.iterations == 0 || self.stride == 0 {
            return Err(EvalError::Invalid(
                "the separation's components, iterations and stride must be positive".into(),
            ));
        }
        Ok(())
    }
}

/// Sun et al. 2018 as a harness [`Method`]: at each k, `diffuse_dims` diffuse and the rest
/// specular coefficients, every k cut from one fit (both PCAs are nested).
#[derive(Clone, Debug, Default)]
pub struct SeparatedMethod {
    config: SeparationConfig,
}

impl SeparatedMethod {
    /// The method with `config`.
    pub fn new(config: SeparationConfig) -> Self {
        Self { config }
    }
}

impl Method for SeparatedMethod {
    fn name(&self) -> String {
        NAME.to_string()
    }

    fn fit(
        &self,
        train: &[&MerlTable],
        names: &[String],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        Ok(self.fit_ks(train, names, &[k], progress)?.remove(0))
    }

    fn fit_ks(
        &self,
        train: &[&MerlTable],
        _names: &[String],
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let k_max = max_k(ks)?;
        let d = self.config.diffuse_dims;
        if let Some(&k) = ks.iter().find(|&&k| k <= d) {
            return Err(EvalError::Invalid(format!(
                "{NAME} at k = {k}: {d} diffuse coefficients leave no specular one"
            )));
        }
        let basis = Arc::new(SeparatedBasis::fit(NAME, &self.config, train, k_max - d, progress)?);
        let shared = Arc::new(SharedEncoding::new(k_max));
        Ok(ks
            .iter()
            .map(|&k| {
                Box::new(SeparatedCodec {
                    basis: Arc::clone(&basis),
                    k,
                    shared: Arc::clone(&shared),
                }) as Box<dyn Codec>
            })
            .collect())
    }
}

/// A [`SeparatedBasis`] cut to `k` coefficients; codecs of one fit share each BRDF's
/// encoding at the largest k.
pub struct SeparatedCodec {
    basis: Arc<SeparatedBasis>,
    k: usize,
    shared: Arc<SharedEncoding>,
}

impl SeparatedCodec {
    /// The fitted basis.
    pub fn basis(&self) -> &Arc<SeparatedBasis> {
        &self.basis
    }
}

impl Codec for SeparatedCodec {
    fn name(&self) -> String {
        format!("{NAME}-{}", self.k)
    }

    fn k(&self) -> usize {
        self.k
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        let code = self.shared.coefficients(table, |t, k| self.basis.encode(t, k))?;
        Ok(code[..self.k].to_vec())
    }

    fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        if code.len() != self.k {
            return Err(EvalError::Invalid(format!(
                "{} expects {} coefficients, got {}",
                self.name(),
                self.k,
                code.len()
            )));
        }
        self.basis.decode(code)
    }
}

#[cfg(test)]
mod tests;

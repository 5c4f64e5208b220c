//! A fitted separated representation (Sun et al. 2018): PCA of the collection's diffuse
//! albedos and PCA of their specular parts in IPCA's mapped space, with the search basis that
//! separates a BRDF it has not seen.

use super::search::{lowest_albedos, separate_all, Sample, SearchBasis};
use super::SeparationConfig;
use crate::baseline::BaselineBasis;
use crate::baseline::Domain;
use crate::error::{EvalError, Result};
use crate::pca::LinearBasis;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::{MerlTable, Progress, Silent};
use std::f64::consts::PI;

/// An albedo change below which the alternation has converged.
const CONVERGED: f64 = 1e-5;

/// The fitted parts of a separated representation.
#[derive(Clone, Debug)]
pub struct SeparatedBasis {
    domain: Domain,
    sample: Sample,
    search: SearchBasis,
    /// PCA of the training albedos (rows of 3), `diffuse_dims` components.
    diffuse: LinearBasis,
    /// IPCA of the specular parts.
    specular: BaselineBasis,
    /// The albedos the separation found for the training BRDFs, in their order.
    training_albedos: Vec<[f64; 3]>,
}

impl SeparatedBasis {
    /// Separates `train` and fits `specular` specular components (Sun et al. 2018, §4): from
    /// each table's smallest value, fit the search basis to the specular parts and move each
    /// albedo to where the BRDF is best explained (the configured number of rounds, or until no
    /// albedo moves); then fit the diffuse and specular PCAs.
    pub fn fit(
        name: &str,
        config: &SeparationConfig,
        train: &[&MerlTable],
        specular: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        let n = train.len();
        config.check(n)?;
        let domain = Domain::common(train)?;
        let sample = Sample::new(&domain, config.stride)?;
        let values: Vec<Vec<f32>> = train.iter().map(|t| sample.values(t)).collect();
        let all: Vec<&[f32]> = values.iter().map(Vec::as_slice).collect();
        // Each half of the training set is separated against a basis fitted to the other, so
        // a BRDF's own split never shapes the basis that judges it (a basis fitted to all of
        // them explains each one's current split, and the albedos creep instead of moving).
        let halves: [Vec<usize>; 2] = [(0..n).step_by(2).collect(), (1..n).step_by(2).collect()];
        // With as many components as rows less one, every row is explained whatever its albedo.
        let components = config.search_components.min((n / 2).saturating_sub(2)).max(1);
        let bounds: Vec<[f64; 3]> = train.iter().map(|t| lowest_albedos(&domain, t)).collect();
        let mut albedos = bounds.clone();
        progress.start(config.iterations as u64, "separating diffuse and specular parts");
        for _ in 0..config.iterations {
            let mut next = albedos.clone();
            for (h, half) in halves.iter().enumerate() {
                let other = &halves[1 - h];
                let rows: Vec<&[f32]> = other.iter().map(|&m| all[m]).collect();
                let found: Vec<[f64; 3]> = other.iter().map(|&m| albedos[m]).collect();
                let search =
                    SearchBasis::fit(&sample, &rows, &found, components, config.specular_epsilon)?;
                let own: Vec<&[f32]> = half.iter().map(|&m| all[m]).collect();
                let own_bounds: Vec<[f64; 3]> = half.iter().map(|&m| bounds[m]).collect();
                for (&m, a) in half.iter().zip(separate_all(&search, &sample, &own, &own_bounds)) {
                    next[m] = a;
                }
            }
            let moved = next
                .iter()
                .zip(&albedos)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0f64, f64::max);
            albedos = next;
            progress.advance(1);
            progress.status(&format!("largest albedo change {moved:.2e}"));
            if moved < CONVERGED {
                break;
            }
        }
        // The search a new BRDF meets, fitted to all; the training BRDFs are separated by it
        // too, so that encoding one of them finds the albedo its specular part was fitted with.
        let components = config.search_components.min(n - 2);
        let search =
            SearchBasis::fit(&sample, &all, &albedos, components, config.specular_epsilon)?;
        let albedos = separate_all(&search, &sample, &all, &bounds);
        progress.finish();
        let rows: Vec<Vec<f32>> =
            albedos.iter().map(|a| a.iter().map(|&x| x as f32).collect()).collect();
        let refs: Vec<&[f32]> = rows.iter().map(Vec::as_slice).collect();
        let diffuse = LinearBasis::fit(&refs, config.diffuse_dims.min(n - 1), &Silent)?;
        let mut less = Vec::with_capacity(n);
        for a in &albedos {
            less.push(diffuse_brdf(&diffuse.decode(&diffuse.encode(&as_row(a), diffuse.k())?)?));
        }
        let less_f32: Vec<[f32; 3]> = less.iter().map(|l| l.map(|x| x as f32)).collect();
        let reference = MedianReference::from_remainders(train, &less_f32)?;
        let eps = config.specular_epsilon;
        let specular =
            BaselineBasis::fit_remainders(name, train, &less, &reference, eps, specular, progress)?;
        Ok(Self { domain, sample, search, diffuse, specular, training_albedos: albedos })
    }

    /// Diffuse coefficients stored per BRDF.
    pub fn diffuse_dims(&self) -> usize {
        self.diffuse.k()
    }

    /// Specular components fitted (the largest k is this plus [`Self::diffuse_dims`]).
    pub fn specular_dims(&self) -> usize {
        self.specular.basis().k()
    }

    /// The albedos the separation found for the training BRDFs (before the diffuse PCA).
    pub fn training_albedos(&self) -> &[[f64; 3]] {
        &self.training_albedos
    }

    /// The diffuse albedo per channel the separation finds for `table`.
    pub fn separate(&self, table: &MerlTable) -> [f64; 3] {
        let bounds = lowest_albedos(&self.domain, table);
        self.search.separate(&self.sample, &self.sample.values(table), bounds)
    }

    /// `k` coefficients of `table`: its albedo's diffuse coefficients, then the specular
    /// coefficients of what is left once the diffuse part they decode to is taken off.
    pub fn encode(&self, table: &MerlTable, k: usize) -> Result<Vec<f32>> {
        let d = self.check_k(k)?;
        let albedo = self.separate(table);
        let mut code = self.diffuse.encode(&as_row(&albedo), d)?;
        let less = diffuse_brdf(&self.diffuse.decode(&code)?);
        code.extend(self.specular.encode_less(table, less, k - d)?);
        Ok(code)
    }

    /// The table of coefficients `code` (`code.len()` is the k used).
    pub fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        let d = self.check_k(code.len())?;
        if let Some(i) = code.iter().position(|c| !c.is_finite()) {
            return Err(EvalError::Invalid(format!("coefficient {i} is {}", code[i])));
        }
        let plus = diffuse_brdf(&self.diffuse.decode(&code[..d])?);
        self.specular.decode_plus(&code[d..], plus)
    }

    /// The diffuse dims of a code of length `k`, or why `k` is out of range.
    fn check_k(&self, k: usize) -> Result<usize> {
        let d = self.diffuse_dims();
        if k < d || k > d + self.specular_dims() {
            return Err(EvalError::Invalid(format!(
                "{k} coefficients from a separated basis of {d} diffuse and {} specular \
                 components",
                self.specular_dims()
            )));
        }
        Ok(d)
    }
}

fn as_row(albedo: &[f64; 3]) -> Vec<f32> {
    albedo.iter().map(|&x| x as f32).collect()
}

/// The Lambertian BRDF `albedo / pi` of a decoded albedo row, each channel at least 0.
fn diffuse_brdf(row: &[f32]) -> [f64; 3] {
    std::array::from_fn(|c| f64::from(row[c]).max(0.0) / PI)
}

//! The PCA and IPCA baselines on MERL tables: a [`Mapping`] of the valid cells ([`Domain`])
//! followed by a [`LinearBasis`] (eq. 5), as a harness [`Method`] ([`BaselineCodec`] its codec).

mod artifact;
mod codec;
mod domain;
mod mapping;

pub use codec::BaselineCodec;
pub(crate) use codec::{max_k, SharedEncoding};
pub use domain::Domain;
pub use mapping::{Mapping, MappingKind};

use crate::error::{EvalError, Result};
use crate::harness::{Codec, FoldTraining, Method};
use crate::pca::LinearBasis;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::{MerlTable, Progress};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// A fitted baseline: domain, mapping and linear basis. Codecs of any `k <= basis.k()` share it.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineBasis {
    name: String,
    domain: Domain,
    mapping: Mapping,
    basis: LinearBasis,
    n_train: usize,
}

impl BaselineBasis {
    /// Fits `kind`'s mapping and `k` components to `train`.
    pub fn fit(
        name: &str,
        kind: MappingKind,
        train: &[&MerlTable],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        Self::fit_with_reference(name, kind, train, None, k, progress)
    }

    /// [`BaselineBasis::fit`] with IPCA's median reference already computed (`median` must be
    /// the per-value median of `train`; computed here when `None`).
    pub fn fit_with_reference(
        name: &str,
        kind: MappingKind,
        train: &[&MerlTable],
        median: Option<&MedianReference>,
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if train.len() < 2 {
            return Err(EvalError::Invalid(format!(
                "{name} needs at least 2 training tables, got {}",
                train.len()
            )));
        }
        let domain = Domain::common(train)?;
        let mapping = match kind {
            MappingKind::Log => Mapping::Log,
            MappingKind::LogRelative => match median {
                Some(median) => Mapping::log_relative(&domain, median.values())?,
                None => {
                    let median = MedianReference::from_tables(train)?;
                    Mapping::log_relative(&domain, median.values())?
                }
            },
        };
        Self::fit_mapped(name, domain, mapping, train, &vec![[0.0; 3]; train.len()], k, progress)
    }

    /// IPCA's mapping and `k` components fitted to what is left of each training table once
    /// `less[t][c]` is taken off every value of channel c: the specular parts of a
    /// diffuse-specular separation ([`crate::separation`]). `reference` must be their median
    /// ([`MedianReference::from_remainders`]); `epsilon` the mapping's eps ([`Mapping::with_epsilon`]).
    pub fn fit_remainders(
        name: &str,
        train: &[&MerlTable],
        less: &[[f64; 3]],
        reference: &MedianReference,
        epsilon: f64,
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if train.len() < 2 || less.len() != train.len() {
            return Err(EvalError::Invalid(format!(
                "{name} needs at least 2 training tables, each with its part to take off (got {} \
                 tables, {} parts)",
                train.len(),
                less.len()
            )));
        }
        let domain = Domain::common(train)?;
        let mapping = Mapping::log_relative(&domain, reference.values())?.with_epsilon(epsilon)?;
        Self::fit_mapped(name, domain, mapping, train, less, k, progress)
    }

    fn fit_mapped(
        name: &str,
        domain: Domain,
        mapping: Mapping,
        train: &[&MerlTable],
        less: &[[f64; 3]],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        let rows: Vec<Vec<f32>> =
            train.iter().zip(less).map(|(t, &l)| mapping.forward_less(&domain, t, l)).collect();
        let refs: Vec<&[f32]> = rows.iter().map(|r| r.as_slice()).collect();
        let basis = LinearBasis::fit(&refs, k, progress)?;
        Ok(Self { name: name.to_string(), domain, mapping, basis, n_train: train.len() })
    }

    /// The method's name ("PCA", "IPCA").
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The cells covered.
    pub fn domain(&self) -> &Domain {
        &self.domain
    }

    /// The value mapping.
    pub fn mapping(&self) -> &Mapping {
        &self.mapping
    }

    /// The linear basis in mapped space.
    pub fn basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// Number of training tables.
    pub fn n_train(&self) -> usize {
        self.n_train
    }

    /// `k` coefficients of `table`. Domain cells invalid in `table` are taken at the mean.
    pub fn encode(&self, table: &MerlTable, k: usize) -> Result<Vec<f32>> {
        self.encode_less(table, [0.0; 3], k)
    }

    /// [`BaselineBasis::encode`] of what is left of `table` once `less[c]` is taken off each
    /// value of channel c (a basis fitted by [`BaselineBasis::fit_remainders`]).
    pub fn encode_less(&self, table: &MerlTable, less: [f64; 3], k: usize) -> Result<Vec<f32>> {
        let mut row = self.mapping.forward_less(&self.domain, table, less);
        for (x, &m) in row.iter_mut().zip(self.basis.mean()) {
            if x.is_nan() {
                *x = m;
            }
        }
        self.basis.encode(&row, k)
    }

    /// The table of coefficients `code` (`code.len()` components used).
    pub fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        self.decode_plus(code, [0.0; 3])
    }

    /// [`BaselineBasis::decode`] with `plus[c]` added to every value of channel c (the
    /// diffuse part of a separated BRDF).
    pub fn decode_plus(&self, code: &[f32], plus: [f64; 3]) -> Result<MerlTable> {
        if let Some(i) = code.iter().position(|c| !c.is_finite()) {
            return Err(EvalError::Invalid(format!("coefficient {i} is {}", code[i])));
        }
        let row = self.basis.decode(code)?;
        self.mapping.inverse_plus(&self.domain, &row, plus)
    }

    /// Writes the basis as an artifact file (atomic: temp file, then rename).
    pub fn save(&self, path: &Path) -> Result<()> {
        artifact::save(self, path)
    }

    /// Reads an artifact written by [`BaselineBasis::save`], checking its header and checksum.
    pub fn load(path: &Path) -> Result<Self> {
        artifact::load(path)
    }

    /// A codec using the first `k` components.
    pub fn codec(self: &Arc<Self>, k: usize) -> Result<BaselineCodec> {
        BaselineCodec::new(self, k)
    }
}

/// PCA or IPCA as a harness [`Method`] ([`BaselineMethod::pca`], [`BaselineMethod::ipca`]).
#[derive(Clone, Debug)]
pub struct BaselineMethod {
    name: String,
    kind: MappingKind,
    /// Whether to keep the latest fitted basis in `last` (see [`BaselineMethod::last_fit`]).
    keep_last: bool,
    last: Arc<Mutex<Option<Arc<BaselineBasis>>>>,
}

impl BaselineMethod {
    /// A baseline named `name` with mapping `kind`.
    pub fn new(name: &str, kind: MappingKind) -> Self {
        Self { name: name.to_string(), kind, keep_last: false, last: Arc::default() }
    }

    /// The paper's "traditional PCA" (§4): natural log of the reflectance
    /// ([`crate::pca::log_map`]), all three channels of a BRDF in one row, mean-centred, truncated
    /// to k components.
    pub fn pca() -> Self {
        Self::new("PCA", MappingKind::Log)
    }

    /// IPCA (§4, Nielsen et al. 2015): PCA after the cosine-weighted log-relative mapping
    /// ([`crate::ipca::cosine_log_relative`]) against the training median.
    pub fn ipca() -> Self {
        Self::new("IPCA", MappingKind::LogRelative)
    }

    /// The same method, keeping the basis of its latest harness fit (to save it as an
    /// artifact afterwards). Off by default: a basis of 40 components over the full grid is
    /// about 0.5 GB.
    pub fn keeping_last_fit(mut self) -> Self {
        self.keep_last = true;
        self
    }

    /// The basis of the latest fit through [`Method::fit_ks`] or [`Method::fit_fold`], when
    /// [`BaselineMethod::keeping_last_fit`] was asked for.
    pub fn last_fit(&self) -> Option<Arc<BaselineBasis>> {
        self.last.lock().ok().and_then(|slot| slot.clone())
    }

    /// Fits one basis of `k` components.
    pub fn fit_basis(
        &self,
        train: &[&MerlTable],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<BaselineBasis> {
        BaselineBasis::fit(&self.name, self.kind, train, k, progress)
    }

    /// One basis at the largest of `ks`, each codec a truncation of it, all sharing one
    /// encoding of each BRDF ([`BaselineCodec::nested`]).
    fn nested_codecs(&self, basis: BaselineBasis, ks: &[usize]) -> Result<Vec<Box<dyn Codec>>> {
        let basis = Arc::new(basis);
        if self.keep_last {
            if let Ok(mut slot) = self.last.lock() {
                *slot = Some(Arc::clone(&basis));
            }
        }
        let codecs = BaselineCodec::nested(&basis, ks)?;
        Ok(codecs.into_iter().map(|c| Box::new(c) as Box<dyn Codec>).collect())
    }
}

impl Method for BaselineMethod {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn fit(
        &self,
        train: &[&MerlTable],
        _names: &[String],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        let basis = Arc::new(self.fit_basis(train, k, progress)?);
        Ok(Box::new(basis.codec(k)?))
    }

    /// One fit at the largest k; every codec is a truncation of it (PCA components are nested).
    fn fit_ks(
        &self,
        train: &[&MerlTable],
        _names: &[String],
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let k_max = max_k(ks)?;
        self.nested_codecs(self.fit_basis(train, k_max, progress)?, ks)
    }

    /// As [`Method::fit_ks`], reusing the fold's median reference for IPCA.
    fn fit_fold(
        &self,
        train: &FoldTraining<'_>,
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let tables = train.tables()?;
        let refs: Vec<&MerlTable> = tables.iter().map(|t| &**t).collect();
        let basis = BaselineBasis::fit_with_reference(
            &self.name,
            self.kind,
            &refs,
            Some(train.reference),
            max_k(ks)?,
            progress,
        )?;
        self.nested_codecs(basis, ks)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::CELLS;
    use deepbrdf_data::testing::{sparse_set, synthetic_set};
    use deepbrdf_data::Silent;

    /// Largest |rho - rho_hat| cos_i cos_o over the domain.
    fn max_weighted_error(a: &MerlTable, b: &MerlTable, domain: &Domain) -> f64 {
        let mut worst = 0f64;
        for &cell in domain.cells() {
            let w = f64::from(deepbrdf_data::merl::grid::cos_weights()[cell as usize]);
            for c in 0..3 {
                let i = c * CELLS + cell as usize;
                worst = worst.max((f64::from(a.values()[i]) - f64::from(b.values()[i])).abs() * w);
            }
        }
        worst
    }

    #[test]
    fn mappings_round_trip_on_tables() {
        let (_, tables) = synthetic_set(3);
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let domain = Domain::common(&refs).unwrap();
        assert_eq!(domain.cells().len(), tables[0].valid_cells());
        let median = MedianReference::from_tables(&refs).unwrap();
        for mapping in [Mapping::Log, Mapping::log_relative(&domain, median.values()).unwrap()] {
            let back = mapping.inverse(&domain, &mapping.forward(&domain, &tables[2])).unwrap();
            assert_eq!(back.mask(), tables[2].mask());
            for &cell in domain.cells().iter().step_by(101) {
                for c in 0..3 {
                    let i = c * CELLS + cell as usize;
                    let (x, y) = (tables[2].values()[i], back.values()[i]);
                    assert!((x - y).abs() <= 1e-5 * (1.0 + x.abs()), "{mapping:?}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn full_rank_codecs_reproduce_their_training_tables() {
        let (names, tables) = sparse_set(5);
        let refs: Vec<&MerlTable> = tables.iter().collect();
        for method in [BaselineMethod::pca(), BaselineMethod::ipca()] {
            let codecs = method.fit_ks(&refs, &names, &[1, 4], &Silent).unwrap();
            assert_eq!(codecs[1].name(), format!("{}-4", method.name()));
            let domain = Domain::common(&refs).unwrap();
            for t in &tables {
                let full = codecs[1].decode(&codecs[1].encode(t).unwrap()).unwrap();
                let err = max_weighted_error(t, &full, &domain);
                assert!(err < 2e-4, "{}: k = n-1 error {err}", method.name());
                let one = codecs[0].decode(&codecs[0].encode(t).unwrap()).unwrap();
                assert!(max_weighted_error(t, &one, &domain) > 1e-3);
            }
            assert!(method.last_fit().is_none(), "kept a fit without being asked");
            assert!(codecs[0].decode(&[0.0, 0.0]).is_err());
            assert!(codecs[0].decode(&[f32::NAN]).is_err());
        }
    }

    /// Remainders (a constant per channel taken off) round-trip through their own mapping, at
    /// any eps; an artifact only holds IPCA's eps, and says so.
    #[test]
    fn remainders_fit_and_decode_back_and_a_custom_eps_is_not_saved() {
        let (_, tables) = sparse_set(4);
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let less = [[0.01, 0.02, 0.0], [0.0; 3], [0.03, 0.0, 0.01], [0.0, 0.01, 0.0]];
        let less32: Vec<[f32; 3]> = less.iter().map(|l| l.map(|x| x as f32)).collect();
        let reference = MedianReference::from_remainders(&refs, &less32).unwrap();
        let domain = Domain::common(&refs).unwrap();
        for eps in [crate::ipca::EPSILON, 0.01] {
            let b = BaselineBasis::fit_remainders("S", &refs, &less, &reference, eps, 3, &Silent)
                .unwrap();
            let code = b.encode_less(&tables[2], less[2], 3).unwrap();
            let back = b.decode_plus(&code, less[2]).unwrap();
            assert!(max_weighted_error(&tables[2], &back, &domain) < 2e-4, "eps {eps}");
            let dir = tempfile::tempdir().unwrap();
            let saved = b.save(&dir.path().join("s.basis"));
            assert_eq!(saved.is_ok(), eps == crate::ipca::EPSILON, "eps {eps}: {saved:?}");
        }
        let mapping = Mapping::log_relative(&domain, reference.values()).unwrap();
        assert!(mapping.with_epsilon(0.0).is_err());
    }

    #[test]
    fn artifact_round_trips_and_rejects_corruption() {
        let (names, tables) = sparse_set(4);
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let dir = tempfile::tempdir().unwrap();
        for method in [BaselineMethod::pca(), BaselineMethod::ipca()] {
            // The basis a harness fit keeps is the one saved (as `experiments baselines
            // --save-basis` does).
            let method = method.keeping_last_fit();
            let codecs = method.fit_ks(&refs, &names, &[1, 2], &Silent).unwrap();
            let basis = method.last_fit().unwrap();
            assert_eq!(basis.basis().k(), 2);
            let code = codecs[1].encode(&tables[1]).unwrap();
            assert_eq!(code, basis.encode(&tables[1], 2).unwrap());
            let path = dir.path().join(format!("{}.basis", method.name()));
            basis.save(&path).unwrap();
            let back = BaselineBasis::load(&path).unwrap();
            assert_eq!(&back, basis.as_ref());
            let code = basis.encode(&tables[1], 2).unwrap();
            assert_eq!(back.decode(&code).unwrap(), basis.decode(&code).unwrap());

            let bytes = std::fs::read(&path).unwrap();
            let mut flipped = bytes.clone();
            let mid = flipped.len() / 2;
            flipped[mid] ^= 0x40;
            let bad = dir.path().join("flipped.basis");
            std::fs::write(&bad, &flipped).unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("checksum") && err.contains("flipped.basis"), "{err}");

            std::fs::write(&bad, &bytes[..bytes.len() - 100]).unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("truncated"), "{err}");

            std::fs::write(&bad, b"P3\n2 2\n255\n").unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("too short") || err.contains("magic"), "{err}");

            // An absurd size in an otherwise well-formed header is refused before allocating.
            let mut absurd = bytes.clone();
            let k_at = 16 + basis.name().len() + 16;
            absurd[k_at..k_at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
            std::fs::write(&bad, &absurd).unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("absurd") && err.contains("flipped.basis"), "{err}");
            // More components than the training set allows.
            let mut inconsistent = bytes.clone();
            inconsistent[k_at..k_at + 8].copy_from_slice(&4u64.to_le_bytes());
            std::fs::write(&bad, &inconsistent).unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("4 components from 4 training"), "{err}");
            // A header claiming a larger (plausible) domain than the file holds.
            let mut bigger = bytes.clone();
            let cells_at = k_at - 8;
            bigger[cells_at..cells_at + 8].copy_from_slice(&1_000_000u64.to_le_bytes());
            std::fs::write(&bad, &bigger).unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("header implies"), "{err}");
            // A file that is a directory, and an empty file.
            let err = BaselineBasis::load(dir.path()).unwrap_err().to_string();
            assert!(err.contains("not a regular file"), "{err}");
            std::fs::write(&bad, b"").unwrap();
            let err = BaselineBasis::load(&bad).unwrap_err().to_string();
            assert!(err.contains("too short"), "{err}");
        }
        let missing = BaselineBasis::load(&dir.path().join("none.basis")).unwrap_err().to_string();
        assert!(missing.contains("none.basis"), "{missing}");
    }
}

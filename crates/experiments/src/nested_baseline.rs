//! PCA and IPCA for a sweep over k: the baselines of `deepbrdf_eval` (one basis fitted at the
//! largest k, each codec a truncation of it) with each BRDF mapped and projected once, at the
//! largest k, for all codecs of the sweep.
//!
//! A coefficient of eq. (5) is the projection `c_j = v_j . (row - mu)` on one component,
//! whatever k is, so the coefficients at k are the first k of those at the largest k: encoding
//! once per BRDF gives exactly what each truncated codec would compute, at a quarter of the cost
//! for k = 5, 10, 20, 40.

use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::baseline::{BaselineBasis, MappingKind};
use deepbrdf_eval::harness::{Codec, FoldTraining, Method};
use deepbrdf_eval::{EvalError, Result};
use std::sync::{Arc, Mutex};

/// A baseline (PCA or IPCA) as a harness [`Method`] that encodes each BRDF once per sweep.
pub struct NestedBaseline {
    name: String,
    kind: MappingKind,
}

impl NestedBaseline {
    /// "Traditional PCA" (§4): natural log of the reflectance.
    pub fn pca() -> Self {
        Self { name: "PCA".into(), kind: MappingKind::Log }
    }

    /// IPCA (Nielsen et al. 2015): the cosine-weighted log-relative mapping.
    pub fn ipca() -> Self {
        Self { name: "IPCA".into(), kind: MappingKind::LogRelative }
    }

    fn codecs(&self, basis: BaselineBasis, ks: &[usize]) -> Vec<Box<dyn Codec>> {
        let k_max = ks.iter().copied().max().unwrap_or(0);
        let shared = Arc::new(Shared { basis, k_max, last: Mutex::new(None) });
        ks.iter()
            .map(|&k| Box::new(NestedCodec { shared: shared.clone(), k }) as Box<dyn Codec>)
            .collect()
    }
}

impl Method for NestedBaseline {
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
        let basis = BaselineBasis::fit(&self.name, self.kind, train, k, progress)?;
        Ok(self.codecs(basis, &[k]).remove(0))
    }

    fn fit_fold(
        &self,
        train: &FoldTraining<'_>,
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let k_max =
            ks.iter().copied().max().ok_or_else(|| EvalError::Invalid("no k given".into()))?;
        let basis = BaselineBasis::fit_with_reference(
            &self.name,
            self.kind,
            train.tables,
            Some(train.reference),
            k_max,
            progress,
        )?;
        Ok(self.codecs(basis, ks))
    }
}

/// The basis of one fold and the coefficients (at the largest k) of the last BRDF encoded.
struct Shared {
    basis: BaselineBasis,
    k_max: usize,
    last: Mutex<Option<(MerlTable, Arc<Vec<f32>>)>>,
}

impl Shared {
    /// The coefficients of `table` at the largest k, computed once per table (keyed by the
    /// table's content).
    fn coefficients(&self, table: &MerlTable) -> Result<Arc<Vec<f32>>> {
        if let Ok(last) = self.last.lock() {
            if let Some((cached, code)) = last.as_ref() {
                if cached == table {
                    return Ok(code.clone());
                }
            }
        }
        let code = Arc::new(self.basis.encode(table, self.k_max)?);
        if let Ok(mut last) = self.last.lock() {
            *last = Some((table.clone(), code.clone()));
        }
        Ok(code)
    }
}

/// The first `k` components of a shared basis.
struct NestedCodec {
    shared: Arc<Shared>,
    k: usize,
}

impl Codec for NestedCodec {
    fn name(&self) -> String {
        format!("{}-{}", self.shared.basis.name(), self.k)
    }

    fn k(&self) -> usize {
        self.k
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        Ok(self.shared.coefficients(table)?[..self.k].to_vec())
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
        self.shared.basis.decode(code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_data::Silent;

    fn table(i: usize) -> MerlTable {
        MerlTable::from_fn(|h, d, p| {
            let v = 0.02 + 0.01 * i as f32 + (-(h as f32 / (3.0 + i as f32)).powi(2)).exp();
            [v, v * (1.0 + 0.001 * d as f32), v * (1.0 + 0.0001 * p as f32 * i as f32)]
        })
    }

    /// The truncated codecs give what the library's own PCA / IPCA codecs give.
    #[test]
    fn same_codes_and_tables_as_the_library_baselines() {
        let tables: Vec<MerlTable> = (0..3).map(table).collect();
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let names: Vec<String> = (0..3).map(|i| format!("m{i}")).collect();
        let reference = MedianReference::from_tables(&refs).unwrap();
        let set = FoldTraining { tables: &refs, names: &names, reference: &reference };
        let ks = [1, 2];
        for (ours, theirs) in [
            (NestedBaseline::pca(), deepbrdf_eval::baseline::BaselineMethod::pca()),
            (NestedBaseline::ipca(), deepbrdf_eval::baseline::BaselineMethod::ipca()),
        ] {
            assert_eq!(ours.name(), theirs.name());
            let a = ours.fit_fold(&set, &ks, &Silent).unwrap();
            let b = theirs.fit_fold(&set, &ks, &Silent).unwrap();
            // The second encoding of the same table comes from the cache.
            for t in [&tables[1], &tables[1]] {
                for (ca, cb) in a.iter().zip(&b) {
                    let (x, y) = (ca.encode(t).unwrap(), cb.encode(t).unwrap());
                    assert_eq!(x.len(), ca.k());
                    for (u, v) in x.iter().zip(&y) {
                        assert!(
                            (u - v).abs() <= 1e-5 * v.abs().max(1.0),
                            "{} {x:?} {y:?}",
                            ca.name()
                        );
                    }
                    if ca.k() == 2 {
                        assert_eq!(ca.decode(&x).unwrap(), cb.decode(&x).unwrap());
                    }
                }
            }
            assert!(a[0].decode(&[0.0, 0.0]).is_err());
            assert!(a[1].encode(&tables[2]).unwrap() != a[1].encode(&tables[0]).unwrap());
        }
    }
}

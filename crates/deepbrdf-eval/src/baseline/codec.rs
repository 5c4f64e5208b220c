//! A fitted baseline basis truncated to k components, as a harness [`Codec`]: the codecs cut
//! from one fit for a sweep over k share one encoding of each BRDF.
//!
//! A coefficient of eq. (5) (Hu et al., CGF 2020, §4) is the projection `c_j = v_j . (row - mu)`
//! on one component, whatever k is, so the coefficients at k are the first k of those at the
//! largest k, to the bit (each is summed on its own, in the same order): encoding once per BRDF
//! at the largest k gives exactly what each truncated codec would compute, at a quarter of the
//! cost for k = 5, 10, 20, 40.

use super::BaselineBasis;
use crate::error::{EvalError, Result};
use crate::harness::Codec;
use deepbrdf_data::MerlTable;
use std::fmt;
use std::sync::{Arc, Mutex};

/// A [`BaselineBasis`] truncated to `k` components.
#[derive(Clone, Debug)]
pub struct BaselineCodec {
    basis: Arc<BaselineBasis>,
    k: usize,
    /// The encoding shared with the other codecs of the same fit ([`BaselineCodec::nested`]).
    shared: Option<Arc<SharedEncoding>>,
}

impl BaselineCodec {
    /// The first `k` components of `basis` (`1 <= k <= basis.basis().k()`).
    pub fn new(basis: &Arc<BaselineBasis>, k: usize) -> Result<Self> {
        if k == 0 || k > basis.basis().k() {
            return Err(EvalError::Invalid(format!(
                "k = {k} from a {} basis of {} components",
                basis.name(),
                basis.basis().k()
            )));
        }
        Ok(Self { basis: Arc::clone(basis), k, shared: None })
    }

    /// One codec per entry of `ks`, in that order, sharing one encoding of each BRDF at the
    /// largest of `ks` (the last BRDF encoded is remembered, keyed by its content).
    pub fn nested(basis: &Arc<BaselineBasis>, ks: &[usize]) -> Result<Vec<Self>> {
        let shared = Arc::new(SharedEncoding::new(max_k(ks)?));
        ks.iter()
            .map(|&k| Ok(Self { shared: Some(Arc::clone(&shared)), ..Self::new(basis, k)? }))
            .collect()
    }

    /// The shared fitted basis.
    pub fn basis(&self) -> &Arc<BaselineBasis> {
        &self.basis
    }
}

impl Codec for BaselineCodec {
    fn name(&self) -> String {
        format!("{}-{}", self.basis.name(), self.k)
    }

    fn k(&self) -> usize {
        self.k
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        match &self.shared {
            Some(shared) => {
                let code = shared.coefficients(table, |t, k| self.basis.encode(t, k))?;
                Ok(code[..self.k].to_vec())
            }
            None => self.basis.encode(table, self.k),
        }
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

/// The largest of `ks` (an error when there is none).
pub(crate) fn max_k(ks: &[usize]) -> Result<usize> {
    ks.iter().copied().max().ok_or_else(|| EvalError::Invalid("no k given".into()))
}

/// The coefficients (at the largest k of a nested set of codecs) of the last BRDF encoded:
/// shared by codecs whose coefficients at k are the first k of those at the largest k.
pub(crate) struct SharedEncoding {
    k_max: usize,
    last: Mutex<Option<(MerlTable, Arc<Vec<f32>>)>>,
}

impl SharedEncoding {
    /// An empty cache for codecs up to `k_max`.
    pub(crate) fn new(k_max: usize) -> Self {
        Self { k_max, last: Mutex::new(None) }
    }

    /// The coefficients of `table` at the largest k (`encode(table, k_max)`), computed once per
    /// table (keyed by the table's content, so another table, or the same values elsewhere in
    /// memory, is never confused with it).
    pub(crate) fn coefficients(
        &self,
        table: &MerlTable,
        encode: impl FnOnce(&MerlTable, usize) -> Result<Vec<f32>>,
    ) -> Result<Arc<Vec<f32>>> {
        if let Ok(last) = self.last.lock() {
            if let Some((cached, code)) = last.as_ref() {
                if cached == table {
                    return Ok(code.clone());
                }
            }
        }
        let code = Arc::new(encode(table, self.k_max)?);
        if let Ok(mut last) = self.last.lock() {
            *last = Some((table.clone(), code.clone()));
        }
        Ok(code)
    }
}

impl fmt::Debug for SharedEncoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SharedEncoding").field("k_max", &self.k_max).finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::MappingKind;
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_data::Silent;

    fn table(i: usize) -> MerlTable {
        MerlTable::from_fn(|h, d, p| {
            let v = 0.02 + 0.01 * i as f32 + (-(h as f32 / (3.0 + i as f32)).powi(2)).exp();
            [v, v * (1.0 + 0.001 * d as f32), v * (1.0 + 0.0001 * p as f32 * i as f32)]
        })
    }

    /// Nested codecs give, to the bit, what a codec of each k alone gives, whatever order the
    /// tables come in (a repeated table is served from the shared encoding).
    #[test]
    fn nested_codecs_encode_exactly_as_codecs_of_each_k_alone() {
        let tables: Vec<MerlTable> = (0..4).map(table).collect();
        let refs: Vec<&MerlTable> = tables[..3].iter().collect();
        let reference = MedianReference::from_tables(&refs).unwrap();
        for kind in [MappingKind::Log, MappingKind::LogRelative] {
            let basis =
                BaselineBasis::fit_with_reference("B", kind, &refs, Some(&reference), 2, &Silent)
                    .unwrap();
            let basis = Arc::new(basis);
            let nested = BaselineCodec::nested(&basis, &[2, 1]).unwrap();
            let alone =
                [BaselineCodec::new(&basis, 2).unwrap(), BaselineCodec::new(&basis, 1).unwrap()];
            for t in [&tables[1], &tables[1], &tables[3], &tables[0], &tables[1]] {
                for (n, a) in nested.iter().zip(&alone) {
                    assert_eq!(n.name(), a.name());
                    let (x, y) = (n.encode(t).unwrap(), a.encode(t).unwrap());
                    assert_eq!(x.len(), n.k());
                    assert_eq!(x, y, "{}", n.name());
                    assert_eq!(n.decode(&x).unwrap(), a.decode(&y).unwrap());
                }
            }
            assert_ne!(
                nested[0].encode(&tables[2]).unwrap(),
                nested[0].encode(&tables[0]).unwrap()
            );
            assert!(nested[1].decode(&[0.0, 0.0]).is_err());
        }
    }

    #[test]
    fn a_k_outside_the_basis_is_refused() {
        let tables: Vec<MerlTable> = (0..3).map(table).collect();
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let basis =
            Arc::new(BaselineBasis::fit("PCA", MappingKind::Log, &refs, 2, &Silent).unwrap());
        for ks in [&[][..], &[0], &[1, 3]] {
            let err = BaselineCodec::nested(&basis, ks).unwrap_err().to_string();
            assert!(err.contains("k") && (err.contains("no k") || err.contains("PCA")), "{err}");
        }
        assert!(BaselineCodec::new(&basis, 3).is_err());
    }
}

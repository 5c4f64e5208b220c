//! The interface every compression method implements, so PCA, IPCA and DeepBRDF run through the
//! same harness: a [`Method`] is fitted to training tables and yields a [`Codec`] of k
//! coefficients per BRDF. Both traits are object safe (`&dyn Method`, `Box<dyn Codec>`).

use crate::error::Result;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::table_set::TableSet;
use deepbrdf_data::{MerlTable, Progress};
use std::borrow::Cow;

/// The training side of one fold as the harness hands it to a [`Method`]: training table `j`
/// is `set.table(indices[j])`, read when asked for ([`FoldTraining::table`]), so a method that
/// needs one table at a time never holds them all.
#[derive(Clone, Copy)]
pub struct FoldTraining<'a> {
    /// The fold's index in the harness' split (0 in in-sample and generalize modes): methods
    /// that keep files per fold (DeepBRDF's model directories) name them by it.
    pub fold: usize,
    pub set: &'a dyn TableSet,
    pub indices: &'a [usize],
    /// `names[j]` names training table `j`.
    pub names: &'a [String],
    /// Eq. (1)'s reference for these tables (their per-value median), computed once per fold
    /// by the harness (the same one its mapped-space measure uses); methods that need it (IPCA,
    /// DeepBRDF) take it from here instead of recomputing it.
    pub reference: &'a MedianReference,
}

impl<'a> FoldTraining<'a> {
    /// Number of training tables.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether there is no training table.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Training table `j`.
    pub fn table(&self, j: usize) -> Result<Cow<'a, MerlTable>> {
        Ok(self.set.table(self.indices[j])?)
    }

    /// Every training table at once (for fits that need them together).
    pub fn tables(&self) -> Result<Vec<Cow<'a, MerlTable>>> {
        (0..self.len()).map(|j| self.table(j)).collect()
    }
}

/// A fitted representation with `k` coefficients per BRDF.
pub trait Codec: Send + Sync {
    /// A short label, e.g. "IPCA-10".
    fn name(&self) -> String;
    /// Number of coefficients per BRDF.
    fn k(&self) -> usize;
    /// The `k` coefficients of `table`.
    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>>;
    /// The full table of `k` coefficients (invalid cells negative, as in MERL files).
    fn decode(&self, code: &[f32]) -> Result<MerlTable>;
}

/// A way of fitting codecs to training BRDFs.
pub trait Method: Sync {
    /// The method's name in tables and plots ("PCA", "IPCA", "DeepBRDF").
    fn name(&self) -> String;

    /// The k of `requested` this method is fitted and scored at (default: all of them). A
    /// method that is costly to fit (DeepBRDF trains one network per fold and k) can run at a
    /// few k while the cheap ones sweep them all; the tables show "-" where a method has none.
    fn ks(&self, requested: &[usize]) -> Vec<usize> {
        requested.to_vec()
    }

    /// Fits a codec of `k` coefficients to `train` (`names[i]` names `train[i]`).
    fn fit(
        &self,
        train: &[&MerlTable],
        names: &[String],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>>;

    /// Fits one codec per entry of `ks`, in that order. The default fits each separately;
    /// methods whose fits are nested (PCA) override it to fit once.
    fn fit_ks(
        &self,
        train: &[&MerlTable],
        names: &[String],
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        ks.iter().map(|&k| self.fit(train, names, k, progress)).collect()
    }

    /// What the harness calls: fits one codec per entry of `ks` on one fold's training set.
    /// The default reads every training table, ignores the precomputed reference and calls
    /// [`Method::fit_ks`].
    fn fit_fold(
        &self,
        train: &FoldTraining<'_>,
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        let tables = train.tables()?;
        let refs: Vec<&MerlTable> = tables.iter().map(|t| &**t).collect();
        self.fit_ks(&refs, train.names, ks, progress)
    }
}

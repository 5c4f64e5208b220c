//! A [`Method`] restricted to some of the harness's k: the cheap baselines sweep every k while
//! a method that trains a network per fold and k (DeepBRDF) runs at the few that matter
//! (`experiments sweep-k --deep-ks`: a network per fold and k is the sweep's costly part).

use super::codec::{Codec, FoldTraining, Method};
use crate::error::Result;
use deepbrdf_data::{MerlTable, Progress};

/// `method` fitted and scored only at those of the requested k that are in `ks`.
pub struct AtKs<'a> {
    method: &'a dyn Method,
    ks: Vec<usize>,
}

impl<'a> AtKs<'a> {
    pub fn new(method: &'a dyn Method, ks: &[usize]) -> Self {
        Self { method, ks: ks.to_vec() }
    }
}

impl Method for AtKs<'_> {
    fn name(&self) -> String {
        self.method.name()
    }

    fn ks(&self, requested: &[usize]) -> Vec<usize> {
        self.method.ks(requested).into_iter().filter(|k| self.ks.contains(k)).collect()
    }

    fn fit(
        &self,
        train: &[&MerlTable],
        names: &[String],
        k: usize,
        progress: &dyn Progress,
    ) -> Result<Box<dyn Codec>> {
        self.method.fit(train, names, k, progress)
    }

    fn fit_ks(
        &self,
        train: &[&MerlTable],
        names: &[String],
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        self.method.fit_ks(train, names, ks, progress)
    }

    fn fit_fold(
        &self,
        train: &FoldTraining<'_>,
        ks: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<Box<dyn Codec>>> {
        self.method.fit_fold(train, ks, progress)
    }
}

//! A trained DeepBRDF model (Hu et al., CGF 2020, §3.2) as a harness [`Codec`]: eq. (2) to
//! encode, eq. (3) to decode.

use super::mapped_input::InputCache;
use super::NAME;
use crate::error::{EvalError, Result};
use crate::harness::Codec;
use deepbrdf_data::MerlTable;
use deepbrdf_model::DeepBrdf;
use std::sync::Arc;

/// A trained model as a codec of its k latent values.
pub struct DeepCodec {
    model: Arc<DeepBrdf>,
    cache: Arc<InputCache>,
}

impl DeepCodec {
    /// The codec of `model`, mapping each table through `cache` (shared by the codecs whose
    /// models map with the same eq. (1) reference).
    pub fn new(model: Arc<DeepBrdf>, cache: Arc<InputCache>) -> Self {
        Self { model, cache }
    }
}

impl Codec for DeepCodec {
    fn name(&self) -> String {
        format!("{NAME}-{}", self.model.k())
    }

    fn k(&self) -> usize {
        self.model.k()
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        let input = self.cache.get(table, self.model.reference());
        input.encode(&self.model).map_err(|e| EvalError::method(self.name(), e))
    }

    fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        self.model.decode(code).map_err(|e| EvalError::method(self.name(), e))
    }
}

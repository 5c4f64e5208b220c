//! DeepBRDF's network input for one BRDF (Hu et al., CGF 2020, §3.2), computed once and reused:
//! the eq. (1) mapping of the table in the §3.2 layout (invalid cells 0) and its validity mask
//! in the same layout ([`deepbrdf_data::network_input::mapped_layout`]). The harness encodes each
//! material with every k, and the Fig. 2 evaluation encodes it from several reduced inputs; all
//! of them start from this, so each table is mapped once per fold.

use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::network_input::mapped_layout;
use deepbrdf_data::MerlTable;
use deepbrdf_model::{DeepBrdf, Result};
use std::sync::{Arc, Mutex};

/// A mapped table in the layout, with its mask.
#[derive(Clone, Debug)]
pub struct MappedInput {
    pub input: Arc<Vec<f32>>,
    pub mask: Arc<Vec<f32>>,
}

impl MappedInput {
    /// Maps `table` with `reference` (eq. 1) into the §3.2 layout, as `DeepBrdf::encode` does.
    pub fn new(table: &MerlTable, reference: &MedianReference) -> Self {
        let (input, mask) = mapped_layout(table, reference);
        Self { input: Arc::new(input), mask: Arc::new(mask) }
    }

    /// Eq. (2) of the full input.
    pub fn encode(&self, model: &DeepBrdf) -> Result<Vec<f32>> {
        model.encode_layout(self.input.to_vec(), self.mask.to_vec())
    }

    /// Eq. (2) from the reduced input of Fig. 2 ([`DeepBrdf::encode_partial_layout`]): only the
    /// phi_d slices in `kept` are used, each missing slice filled from its nearest kept one.
    pub fn encode_partial(&self, model: &DeepBrdf, kept: &[usize]) -> Result<Vec<f32>> {
        model.encode_partial_layout(self.input.to_vec(), self.mask.to_vec(), kept)
    }
}

/// The [`MappedInput`] of the last table seen, shared by codecs whose models have the same
/// eq. (1) reference (those of one fold). Keyed by the table's content, so a different table
/// (or the same values elsewhere in memory) is never confused with it.
#[derive(Default)]
pub struct InputCache {
    slot: Mutex<Option<(MerlTable, MappedInput)>>,
}

impl InputCache {
    /// The mapped input of `table` under `reference` (which must be the same for every caller
    /// of this cache).
    pub fn get(&self, table: &MerlTable, reference: &MedianReference) -> MappedInput {
        if let Ok(slot) = self.slot.lock() {
            if let Some((cached, input)) = slot.as_ref() {
                if cached == table {
                    return input.clone();
                }
            }
        }
        let input = MappedInput::new(table, reference);
        if let Ok(mut slot) = self.slot.lock() {
            *slot = Some((table.clone(), input.clone()));
        }
        input
    }
}

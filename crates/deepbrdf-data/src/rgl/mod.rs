//! Real measured BRDFs of the RGL material database (Dupuy & Jakob 2018, the "EPFL dataset" of
//! the paper's Fig. 9): the tensor-file container, the adaptive parameterization's 2-D warps,
//! the reference RGB evaluator, tabulation onto the MERL grid, and the writer that exports a
//! MERL table in the format (the microfacet retrieval it needs, the container's writer) with
//! the directional albedo that checks it.
pub mod albedo;
pub mod bundled;
pub mod evaluate;
pub mod export;
pub mod microfacet;
pub mod tabulate;
pub mod tensor;
mod tensor_write;
pub mod warp;

#[cfg(test)]
mod export_tests;
#[cfg(test)]
mod tests;

pub use evaluate::RglBrdf;
pub use export::{export, ExportResolution};
pub use tabulate::{tabulate, tabulate_with, CellRule, RGL_TABULATOR_VERSION};
pub use tensor::{Dtype, Field, TensorFile};

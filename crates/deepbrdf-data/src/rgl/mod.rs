//! Real measured BRDFs of the RGL material database (Dupuy & Jakob 2018, the "EPFL dataset" of
//! the paper's Fig. 9): the tensor-file container, the adaptive parameterization's 2-D warps,
//! the reference RGB evaluator, and tabulation onto the MERL grid.
pub mod bundled;
pub mod evaluate;
pub mod tabulate;
pub mod tensor;
pub mod warp;

#[cfg(test)]
mod tests;

pub use evaluate::RglBrdf;
pub use tabulate::{tabulate, tabulate_with, CellRule, RGL_TABULATOR_VERSION};
pub use tensor::{Dtype, Field, TensorFile};

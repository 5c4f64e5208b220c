//! `deepbrdf-eval`: evaluation of measured-BRDF representations (Hu et al., CGF 2020, §4):
//! the PCA and IPCA baselines, DeepBRDF as a method of the evaluation harness shared with them,
//! Sun et al. 2018's diffuse-specular separation (Fig. 8), the robustness to missing phi_d
//! slices (Fig. 2), attribute editing (§5.1), the recovery
//! baselines and targets (§5.2), and figures.
pub mod attributes;
pub mod baseline;
pub mod deep;
pub mod editing;
pub mod error;
pub mod figures;
pub mod golden;
pub mod harness;
pub mod ipca;
pub mod metrics;
pub mod pca;
pub mod recovery;
pub mod robustness;
pub mod round_trip;
pub mod saved_sweep;
pub mod separation;
pub mod stats;
pub mod sweep_report;

pub use error::{EvalError, Result};

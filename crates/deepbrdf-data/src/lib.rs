//! `deepbrdf-data`: measured BRDF data for DeepBRDF (Hu et al., CGF 2020, §3.1).
pub mod albedo;
pub mod augment;
pub mod bundled;
pub mod cache;
pub mod corpus;
pub mod dataset;
pub mod error;
pub mod fetch;
pub mod files;
pub mod ggx;
pub mod gram_pca;
pub mod layout;
pub mod lock;
pub mod mapping;
pub mod merl;
pub mod named;
pub mod nbrdf;
pub mod network_input;
pub mod packed;
pub mod progress;
pub mod rgl;
pub mod summary;
pub mod table_set;
pub mod testing;

pub use error::{DataError, Result};
pub use merl::MerlTable;
pub use progress::{Progress, Silent};

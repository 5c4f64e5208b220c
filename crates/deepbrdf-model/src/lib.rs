//! `deepbrdf-model`: the DeepBRDF networks on Burn (Hu et al., CGF 2020, §3.2).
//!
//! - [`autoencoder`]: Table 1 and the CPU preset; [`loss`]: eq. (4).
//! - [`training_set`], [`train`]: mapped layouts, Adam, checkpoints that resume exactly.
//! - [`artifact`]: the self-contained saved model; [`codec`]: encode / decode with it;
//!   [`compact`]: the spectral basis in the compact form the codec decodes with.
//! - [`fit`]: all of the above on a set of MERL tables.
pub mod artifact;
mod atomic;
pub mod autoencoder;
pub mod codec;
pub mod compact;
mod container;
pub mod device;
pub mod error;
pub mod fit;
pub mod loss;
pub mod preset;
pub mod principal;
pub mod spectral;
pub mod timing;
pub mod train;
pub mod training_set;

pub use artifact::{ModelArtifact, Provenance};
pub use autoencoder::{Autoencoder, AutoencoderConfig};
pub use burn;
pub use codec::DeepBrdf;
pub use device::DeviceKind;
pub use error::{ModelError, Result};
pub use fit::fit;
pub use preset::Preset;
pub use train::{train, EpochRecord, SliceDropoutConfig, TrainConfig, Trained};
pub use training_set::TrainingSet;

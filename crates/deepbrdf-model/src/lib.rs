//! `deepbrdf-model`: the DeepBRDF networks on Burn (Hu et al., CGF 2020, §3.2).
//!
//! - [`autoencoder`]: the architectures, one folder per network family: Table 1
//!   ([`autoencoder::convolutional`]) and the shipped `slice` preset's network shared across
//!   phi_d slices ([`autoencoder::slice`]: its basis, extra training BRDFs ([`augmentation`])
//!   and encoding by optimisation through the decoder ([`refine`])); [`loss`]: eq. (4).
//! - [`train`]: one training loop for every network (schedule, seeded batches, checkpoints
//!   that resume exactly, NaN stop, CSV log), and the autoencoder's training through it, each
//!   family with its own step; [`training_set`]: the mapped layouts it trains on.
//! - [`autoencoder::artifact`]: the self-contained saved model, in the one container every
//!   saved network shares (manifest, id, parts' checksums, atomic writes); [`codec`]: encode /
//!   decode with it.
//! - [`fit`]: all of the above on a set of MERL tables.
//! - [`recovery`]: single-image recovery (§5.2): the CNN from a photo to the latent, Fig. 15.
mod artifact;
pub mod autoencoder;
pub mod codec;
pub mod device;
pub mod error;
pub mod fit;
pub mod loss;
pub mod preset;
mod read_back;
mod record;
pub mod recovery;
pub mod regressor;
pub mod seeded;
pub mod shipped;
pub mod stages;
pub mod streamed;
pub mod timing;
pub mod train;
pub mod training_set;

pub use autoencoder::artifact::{ModelArtifact, Provenance};
pub use autoencoder::slice::{augmentation, refine};
pub use autoencoder::train::{train, train_within, SliceDropoutConfig, TrainConfig, Trained};
pub use autoencoder::{Autoencoder, AutoencoderConfig};
pub use burn;
pub use codec::DeepBrdf;
pub use device::DeviceKind;
pub use error::{ModelError, Result};
pub use fit::fit;
pub use preset::Preset;
pub use regressor::Regressor;
pub use shipped::DEFAULT_MODEL_DIR;
pub use streamed::StreamedTables;
pub use train::EpochRecord;
pub use training_set::TrainingSet;

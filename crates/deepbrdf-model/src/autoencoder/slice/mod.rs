//! The `slice` network, the shipped model's (not Table 1, but the paper's premise of one
//! network shared across phi_d slices, sized to ship): its settings ([`config`]), the basis
//! shared by the images of all phi_d slices and the principal components ([`basis`]), the
//! network ([`network`], with its MLPs, [`mlp`]), the extra training BRDFs ([`augmentation`]),
//! its training step on coefficients ([`step`]) and encoding by optimisation through its
//! decoder ([`refine`]).
//!
//! The name: "slice" is also a phi_d slice of a BRDF (an image of the §3.2 layout) and the
//! slice-dropout augmentation. The network keeps it because it is the network's name in every
//! file and command that refers to it: the preset `slice` (`--preset slice`), the
//! `"architecture": {"slice": ...}` key of each saved `train_config.json` and `model.json`
//! (the shipped `models/default` included). Renaming the Rust types alone would make the code
//! and the files disagree; renaming both would orphan every saved model. In this module
//! "slice" names the network; a single phi_d slice is called an image, and slice dropout is
//! [`crate::autoencoder::train::SliceDropoutConfig`].

pub mod augmentation;
pub mod basis;
pub mod config;
mod mlp;
pub mod network;
pub mod refine;
pub(crate) mod step;

pub use config::{SliceConfig, SLICE_DIRECTIONS};
pub use network::SliceNetwork;

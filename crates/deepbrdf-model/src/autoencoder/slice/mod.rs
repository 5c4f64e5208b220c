//! The `slice` network, the shipped model's (not Table 1, but the paper's premise of one
//! network shared across phi_d slices, sized to ship): its settings ([`config`]), the basis
//! shared by the images of all phi_d slices and the principal components ([`basis`]), the
//! network ([`network`], with its MLPs, [`mlp`]), the extra training BRDFs ([`augmentation`]),
//! its training step on coefficients ([`step`]) and encoding by optimisation through its
//! decoder ([`refine`]).

pub mod augmentation;
pub mod basis;
pub mod config;
mod mlp;
pub mod network;
pub mod refine;
pub(crate) mod step;

pub use config::{SliceConfig, SLICE_DIRECTIONS};
pub use network::SliceNetwork;

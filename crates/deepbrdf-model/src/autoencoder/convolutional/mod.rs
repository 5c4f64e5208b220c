//! Table 1's network (Hu et al., CGF 2020, §3.2), the `paper` preset: its layers' settings
//! ([`config`]), the network ([`network`]), its convolutions as matrix products ([`gemm`]) and
//! its training step on the full layouts ([`step`]) and a per-layer profile of its passes
//! ([`profile`]).

pub mod config;
pub(crate) mod gemm;
pub mod network;
pub mod profile;
pub(crate) mod step;

#[cfg(test)]
mod tests;

pub use config::{ConvAlgorithm, ConvolutionalConfig};
pub use network::{Convolutional, BOTTLENECK_SIDE};

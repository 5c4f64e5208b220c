//! Table 1's network (Hu et al., CGF 2020, §3.2), the `paper` preset: its layers' settings
//! ([`config`]), the network ([`network`]) and its training step on the full layouts
//! ([`step`]).

pub mod config;
pub mod network;
pub(crate) mod step;

pub use config::ConvolutionalConfig;
pub use network::{Convolutional, BOTTLENECK_SIDE};

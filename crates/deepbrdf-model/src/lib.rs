//! `deepbrdf-model`: the DeepBRDF networks on Burn.
pub mod device;

pub use burn;
pub use device::DeviceKind;

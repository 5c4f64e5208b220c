//! Run-time choice of the compute device among the backends compiled in (cargo features
//! `flex` (default), `ndarray`, `wgpu`, `cuda`).

use std::str::FromStr;

/// A backend this binary can run on, chosen with `--device`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DeviceKind {
    /// burn-flex, the fast portable CPU backend (the default).
    Flex,
    /// burn-ndarray, the legacy CPU backend.
    Ndarray,
    /// wgpu (WGSL), any GPU with Vulkan, Metal or DX12.
    Wgpu,
    /// CUDA, NVIDIA GPUs.
    Cuda,
}

// Every kind, compiled in or not, by its cargo feature's name (the `--device` name).
deepbrdf_data::named_enum!(DeviceKind {
    Flex => "flex",
    Ndarray => "ndarray",
    Wgpu => "wgpu",
    Cuda => "cuda",
});

impl DeviceKind {
    /// Whether this binary was built with the kind's cargo feature.
    pub fn is_compiled(self) -> bool {
        match self {
            DeviceKind::Flex => cfg!(feature = "flex"),
            DeviceKind::Ndarray => cfg!(feature = "ndarray"),
            DeviceKind::Wgpu => cfg!(feature = "wgpu"),
            DeviceKind::Cuda => cfg!(feature = "cuda"),
        }
    }

    /// The kinds compiled into this binary, the default first.
    pub fn available() -> Vec<DeviceKind> {
        Self::ALL.into_iter().filter(|k| k.is_compiled()).collect()
    }

    /// The default kind: the first compiled in (flex in a default build).
    pub fn default_kind() -> Option<DeviceKind> {
        Self::available().into_iter().next()
    }

    /// The Burn device of this kind, or an error naming the feature to build with.
    pub fn device(self) -> Result<burn::tensor::Device, String> {
        #[allow(unused_imports)]
        use burn::tensor::Device;
        match self {
            #[cfg(feature = "flex")]
            DeviceKind::Flex => Ok(Device::flex()),
            #[cfg(feature = "ndarray")]
            #[allow(deprecated)]
            DeviceKind::Ndarray => Ok(Device::ndarray()),
            #[cfg(feature = "wgpu")]
            DeviceKind::Wgpu => Ok(Device::wgpu(Default::default())),
            #[cfg(feature = "cuda")]
            DeviceKind::Cuda => Ok(Device::cuda(0)),
            #[allow(unreachable_patterns)]
            other => Err(format!(
                "device '{other}' is not compiled into this binary (rebuild with `--features {other}`)"
            )),
        }
    }
}

impl FromStr for DeviceKind {
    type Err = String;

    /// Parses a device name; refuses kinds not compiled in, naming the feature to build with.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let kind = Self::from_name(s).ok_or_else(|| {
            format!("unknown device '{s}': expected one of flex, ndarray, wgpu, cuda")
        })?;
        if !kind.is_compiled() {
            let have: Vec<_> = Self::available().iter().map(|k| k.name()).collect();
            return Err(format!(
                "device '{kind}' is not compiled into this binary (rebuild with `--features {kind}`); available: {}",
                have.join(", ")
            ));
        }
        Ok(kind)
    }
}

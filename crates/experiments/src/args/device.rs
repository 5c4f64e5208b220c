//! The global `--device` flag: which compiled-in backend runs the networks.
use anyhow::anyhow;
use deepbrdf_model::burn::tensor::Device;
use deepbrdf_model::DeviceKind;
use std::sync::OnceLock;

static SELECTED: OnceLock<Option<DeviceKind>> = OnceLock::new();

/// Records the `--device` choice (called once, before dispatch).
pub fn select(kind: Option<DeviceKind>) {
    let _ = SELECTED.set(kind);
}

/// The selected kind, or the default (the first compiled in).
pub fn kind() -> anyhow::Result<DeviceKind> {
    match SELECTED.get().copied().flatten() {
        Some(kind) => Ok(kind),
        None => DeviceKind::default_kind()
            .ok_or_else(|| anyhow!("no compute backend is compiled into this binary")),
    }
}

/// The selected device.
pub fn device() -> anyhow::Result<Device> {
    kind()?.device().map_err(|e| anyhow!(e))
}

//! Seeded draws from Burn's random generator. Burn keeps one generator per device, shared by
//! the whole process: two models initialised at once (two trainings in one process, as in the
//! test suite) would interleave their draws. Seeding and drawing therefore happen under one
//! process-wide lock.

use std::sync::Mutex;

use burn::prelude::*;

static GENERATOR: Mutex<()> = Mutex::new(());

/// Runs `draw` (which initialises a module or draws random tensors on `device`) right after
/// seeding the device's generator with `seed`, with no other seeded draw in between.
pub fn with_seed<T>(seed: u64, device: &Device, draw: impl FnOnce() -> T) -> T {
    let _guard = GENERATOR.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    device.seed(seed);
    draw()
}

/// Runs `draw` with no seeded draw in progress, for draws whose values do not matter (a
/// network built to load weights into): they must not fall between another thread's seeding
/// and its draws.
pub fn exclusive<T>(draw: impl FnOnce() -> T) -> T {
    let _guard = GENERATOR.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    draw()
}

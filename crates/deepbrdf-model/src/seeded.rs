//! Seeded draws from Burn's random generator. Burn keeps one generator per device, shared by
//! the whole process: two models initialised at once (two trainings in one process, as in the
//! test suite) would interleave their draws. Seeding and drawing therefore happen under one
//! process-wide lock.
//!
//! Burn's initialisers are lazy: a parameter draws its values when first read, not when its
//! module is built. A seeded module is therefore read through, parameter by parameter in field
//! order, before the lock is released; otherwise its draws would happen at its first forward
//! pass, where another thread's seeding can fall in between.

use std::convert::Infallible;
use std::sync::Mutex;

use burn::module::{ModuleVisitor, Param};
use burn::prelude::*;

static GENERATOR: Mutex<()> = Mutex::new(());

/// Reads every float parameter, which draws those not drawn yet.
struct Materialise;

impl ModuleVisitor for Materialise {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let _ = param.val();
    }
}

/// Builds a module with `build` right after seeding `device`'s generator with `seed`, and draws
/// all its weights, with no other seeded draw in between.
pub fn with_seed<M: Module>(seed: u64, device: &Device, build: impl FnOnce() -> M) -> M {
    match try_with_seed(seed, device, || Ok::<M, Infallible>(build())) {
        Ok(module) => module,
        Err(never) => match never {},
    }
}

/// [`with_seed`] for a build that can fail.
pub fn try_with_seed<M: Module, E>(
    seed: u64,
    device: &Device,
    build: impl FnOnce() -> Result<M, E>,
) -> Result<M, E> {
    let _guard = GENERATOR.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    device.seed(seed);
    let module = build()?;
    module.visit(&mut Materialise);
    Ok(module)
}

/// Runs `draw` with no seeded draw in progress, for draws whose values do not matter (a
/// network built to load weights into): they must not fall between another thread's seeding
/// and its draws.
pub fn exclusive<T>(draw: impl FnOnce() -> T) -> T {
    let _guard = GENERATOR.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    draw()
}

#[cfg(test)]
mod tests {
    use burn::nn::{Linear, LinearConfig};

    use super::*;

    fn weights(linear: &Linear) -> Vec<f32> {
        linear.weight.val().into_data().try_into_vec().unwrap()
    }

    #[test]
    fn a_seeded_module_is_drawn_before_another_seeding() {
        let device = Device::default();
        let first = with_seed(7, &device, || LinearConfig::new(5, 4).init(&device));
        assert!(first.weight.is_initialized());
        assert!(first.bias.as_ref().is_some_and(|bias| bias.is_initialized()));
        // Another thread seeding the shared generator after the build, before the first use.
        exclusive(|| device.seed(99));
        let again = with_seed(7, &device, || LinearConfig::new(5, 4).init(&device));
        assert_eq!(weights(&first), weights(&again));
    }
}

//! Reading a tensor's values back from its device, as an error and never a panic: Burn's
//! `into_data` panics when the device failed (on Mesa's lavapipe, a buffer over its 128 MiB
//! limit: "can't allocate buffer of size ..."); `try_into_data` reports it.

use crate::error::{ModelError, Result};
use burn::prelude::*;

/// The values of `t` as f32, or an error saying what `what` was and why it could not be read.
pub(crate) fn values<const D: usize>(t: Tensor<D>, what: &str) -> Result<Vec<f32>> {
    t.try_into_data()
        .map_err(|e| {
            ModelError::Invalid(format!("reading {what} back from the device failed: {e:?}"))
        })?
        .try_into_vec()
        .map_err(|e| ModelError::Invalid(format!("reading {what} as f32 failed: {e:?}")))
}

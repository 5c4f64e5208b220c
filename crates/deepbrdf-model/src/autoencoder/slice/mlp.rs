//! The slice network's MLPs: three linear layers with leaky ReLUs between them, the last at
//! zero so that an untrained network is its linear path (PCA within the slice basis' span).

use burn::nn::{Initializer, Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;

/// Three linear layers `from -> hidden -> hidden -> to`, the hidden ones from `init`, the last
/// at zero (none without `hidden`), so an untrained MLP adds nothing to the linear path.
pub(crate) fn mlp_layers(
    from: usize,
    hidden: Option<usize>,
    to: usize,
    init: &Initializer,
    device: &Device,
) -> Vec<Linear> {
    let Some(h) = hidden else { return Vec::new() };
    let layer = |a: usize, b: usize, init: &Initializer| {
        LinearConfig::new(a, b).with_initializer(init.clone()).init(device)
    };
    vec![layer(from, h, init), layer(h, h, init), layer(h, to, &Initializer::Zeros)]
}

/// `layers` applied in turn with leaky ReLUs between them; `None` without layers.
pub(crate) fn mlp_forward(layers: &[Linear], x: Tensor<2>, slope: f64) -> Option<Tensor<2>> {
    let last = layers.len().checked_sub(1)?;
    let mut x = x;
    for (i, layer) in layers.iter().enumerate() {
        x = layer.forward(x);
        if i < last {
            x = leaky_relu(x, slope);
        }
    }
    Some(x)
}

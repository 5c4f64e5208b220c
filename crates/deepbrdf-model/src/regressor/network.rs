//! The regressor network of eq. (7) / Fig. 11: one hidden layer of 100 units with leaky ReLU,
//! 7 attributes in, k latent values out (standardised: see [`super::scaling`]).

use burn::nn::{Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;
use serde::{Deserialize, Serialize};

/// Number of inputs: the 7 attributes of §5.1.
pub const ATTRIBUTES: usize = 7;

/// The shape of the network (Fig. 11: 7 -> 100 -> k).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NetworkShape {
    /// Hidden units (the paper's 100).
    pub hidden: usize,
    /// Outputs: k.
    pub outputs: usize,
    /// Slope of the leaky ReLU for negative inputs.
    pub negative_slope: f64,
}

/// 7 -> hidden (leaky ReLU) -> k.
#[derive(Module, Debug)]
pub struct RegressorNet {
    hidden: Linear,
    out: Linear,
}

impl RegressorNet {
    /// A network of `shape`, initialised from the device's generator (seed it first, with
    /// [`crate::seeded::with_seed`]).
    pub fn init(shape: &NetworkShape, device: &Device) -> Self {
        let net = Self {
            hidden: LinearConfig::new(ATTRIBUTES, shape.hidden).init(device),
            out: LinearConfig::new(shape.hidden, shape.outputs).init(device),
        };
        // Burn draws parameters lazily, on first use: draw them now, under the caller's seed.
        let _ = net.clone().into_record();
        net
    }

    /// `[batch, 7]` standardised features to `[batch, k]` standardised targets.
    pub fn forward(&self, x: Tensor<2>, negative_slope: f64) -> Tensor<2> {
        self.out.forward(leaky_relu(self.hidden.forward(x), negative_slope))
    }
}

//! The recovery CNN of Fig. 15 (Hu et al. 2020, §5.2): a colour image through three
//! convolutions (the first two each followed by a 2x2 max-pooling, "to preserve more highlight
//! details and retain colour information") and two fully connected layers to the k latent
//! values. The paper gives the layer counts, not their widths; [`RecoveryConfig`] holds them.

use burn::nn::conv::{Conv2d, Conv2dConfig};
use burn::nn::pool::MaxPool2dConfig;
use burn::nn::{Linear, LinearConfig, PaddingConfig2d};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;

use crate::error::ModelError;

/// The CNN's layers.
#[derive(Config, Debug)]
pub struct RecoveryConfig {
    /// Side of the square input image (the paper: 256).
    pub input_side: usize,
    /// Output channels of the three convolutions.
    pub channels: [usize; 3],
    /// Kernel sides of the three convolutions (padded to keep the side at stride 1).
    pub kernels: [usize; 3],
    /// Strides of the three convolutions.
    pub strides: [usize; 3],
    /// Width of the first fully connected layer.
    pub hidden: usize,
    /// Outputs: k latent values (or 7 attributes).
    pub outputs: usize,
    /// Slope of the leaky ReLUs.
    #[config(default = 0.01)]
    pub negative_slope: f64,
}

impl RecoveryConfig {
    /// The image side after each convolution and pooling: `[conv1, pool1, conv2, pool2, conv3]`.
    pub fn sides(&self) -> [usize; 5] {
        let conv = |n: usize, i: usize| {
            let (k, s) = (self.kernels[i], self.strides[i]);
            (n + 2 * (k / 2)).saturating_sub(k) / s.max(1) + 1
        };
        let c1 = conv(self.input_side, 0);
        let p1 = c1 / 2;
        let c2 = conv(p1, 1);
        let p2 = c2 / 2;
        [c1, p1, c2, p2, conv(p2, 2)]
    }

    /// Inputs of the first fully connected layer.
    pub fn flat_features(&self) -> usize {
        let side = self.sides()[4];
        self.channels[2] * side * side
    }

    /// Checks the sizes (every layer at least 1 pixel, odd kernels, positive widths).
    pub fn validate(&self) -> crate::error::Result<()> {
        let positive = self.channels.iter().chain(&self.strides).all(|&v| v > 0)
            && self.hidden > 0
            && self.outputs > 0;
        let odd = self.kernels.iter().all(|&k| k % 2 == 1);
        let sides = self.sides();
        if !positive || !odd || sides.contains(&0) || self.input_side < 4 || self.input_side > 4096
        {
            return Err(ModelError::Invalid(format!(
                "recovery CNN {self:?}: needs positive widths and strides, odd kernels and an \
                 input side of 4 to 4096 that every layer keeps at least 1 pixel wide (sides \
                 {sides:?})"
            )));
        }
        Ok(())
    }

    /// The network, freshly initialised from the device's generator (seed it with
    /// [`crate::seeded::with_seed`]).
    pub fn init(&self, device: &Device) -> crate::error::Result<RecoveryNet> {
        self.validate()?;
        let conv = |c_in: usize, i: usize| {
            let k = self.kernels[i];
            Conv2dConfig::new([c_in, self.channels[i]], [k, k])
                .with_stride([self.strides[i]; 2])
                .with_padding(PaddingConfig2d::Explicit(k / 2, k / 2, k / 2, k / 2))
                .init(device)
        };
        Ok(RecoveryNet {
            conv1: conv(3, 0),
            conv2: conv(self.channels[0], 1),
            conv3: conv(self.channels[1], 2),
            fc1: LinearConfig::new(self.flat_features(), self.hidden).init(device),
            fc2: LinearConfig::new(self.hidden, self.outputs).init(device),
            negative_slope: self.negative_slope,
        })
    }
}

/// The recovery CNN.
#[derive(Module, Debug)]
pub struct RecoveryNet {
    conv1: Conv2d,
    conv2: Conv2d,
    conv3: Conv2d,
    fc1: Linear,
    fc2: Linear,
    negative_slope: f64,
}

impl RecoveryNet {
    /// The network's raw outputs (standardised targets; see [`super::artifact`]).
    ///
    /// # Shapes
    /// - images: `[batch, 3, side, side]` -> `[batch, outputs]`
    pub fn forward(&self, images: Tensor<4>) -> Tensor<2> {
        let slope = self.negative_slope;
        let pool = MaxPool2dConfig::new([2, 2]).init();
        let batch = images.dims()[0];
        let x = leaky_relu(self.conv1.forward(images), slope); // [batch, c1, s1, s1]
        let x = pool.forward(x); // [batch, c1, s1/2, s1/2]
        let x = leaky_relu(self.conv2.forward(x), slope); // [batch, c2, s2, s2]
        let x = pool.forward(x); // [batch, c2, s2/2, s2/2]
        let x = leaky_relu(self.conv3.forward(x), slope); // [batch, c3, s3, s3]
        let [_, c, h, w] = x.dims();
        let x = x.reshape([batch, c * h * w]); // [batch, c3*s3*s3]
        let x = leaky_relu(self.fc1.forward(x), slope); // [batch, hidden]
        self.fc2.forward(x) // [batch, outputs]
    }
}

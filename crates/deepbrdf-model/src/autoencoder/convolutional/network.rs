//! Table 1's convolutional autoencoder (Hu et al., CGF 2020, §3.2): three 3x3 stride-2
//! convolutions (540 -> 256 -> 128 -> 64 channels, 90 -> 45 -> 23 -> 12 pixels), residual
//! blocks at 64 x 12 x 12, FC to k, FC back and three deconvolutions to 128 x 24 x 24,
//! 256 x 48 x 48 and 540 x 90 x 90 (the last 4x4), with PyTorch's padding conventions (spelled
//! out at each layer); optionally narrower, behind a per-pixel projection of the 540 channels,
//! and around a fixed offset and scale.

use burn::module::Param;
use burn::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d, ConvTranspose2dConfig};
use burn::nn::{Initializer, Linear, LinearConfig, PaddingConfig2d};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;
use burn::tensor::Distribution;

use deepbrdf_data::layout::{SIDE as INPUT_SIDE, SLICE_CHANNELS as INPUT_CHANNELS};

use super::config::{ConvAlgorithm, ConvolutionalConfig};
use crate::autoencoder::init::initializers;

/// Side of the bottleneck images after three stride-2 convolutions (90 -> 45 -> 23 -> 12).
pub const BOTTLENECK_SIDE: usize = 12;

/// A zero offset (set with [`crate::Autoencoder::with_offset`]), not trained.
fn zero_offset(device: &Device) -> Param<Tensor<3>> {
    Param::from_tensor(Tensor::zeros([INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], device))
        .set_require_grad(false)
}

/// A unit scale (set with [`crate::Autoencoder::with_scale`]), not trained.
fn unit_scale(device: &Device) -> Param<Tensor<3>> {
    Param::from_tensor(Tensor::ones([INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], device))
        .set_require_grad(false)
}

/// The convolutional encoder and decoder.
#[derive(Module, Debug)]
pub struct Convolutional {
    project_in: Option<Projection>,
    pub(super) down: Vec<Conv2d>,
    pub(super) residual: Vec<ResidualBlock>,
    pub(super) to_latent: Linear,
    pub(super) from_latent: Linear,
    pub(super) up: Vec<ConvTranspose2d>,
    project_out: Option<Projection>,
    /// Fixed per-value offset (the training mean in mapped space), not trained.
    pub(crate) offset: Option<Param<Tensor<3>>>,
    /// Fixed per-value scale (the training spread in mapped space), not trained: inputs are
    /// divided by it and outputs multiplied.
    pub(crate) scale: Option<Param<Tensor<3>>>,
    bottleneck_channels: usize,
    pub(crate) latent: usize,
    negative_slope: f64,
    /// How the convolutions are computed (not a parameter: set by the configuration, or
    /// [`Convolutional::with_conv`]).
    #[module(skip)]
    pub(super) conv: ConvAlgorithm,
}

impl Convolutional {
    /// The layers of `layers` for latent dimension `latent` and leaky ReLU slope
    /// `negative_slope`, freshly initialised (the layers are built in a fixed order: eager
    /// draws first, lazy ones when the record is first taken).
    pub(crate) fn new(
        latent: usize,
        negative_slope: f64,
        layers: &ConvolutionalConfig,
        device: &Device,
    ) -> Self {
        let [e0, e1, e2] = layers.encoder_channels;
        let [d0, d1] = layers.decoder_channels;
        let first = layers.projection.unwrap_or(INPUT_CHANNELS);
        let (hidden, linear) = initializers(layers.he_init, negative_slope);
        let down = |c_in: usize, c_out: usize| {
            Conv2dConfig::new([c_in, c_out], [3, 3])
                .with_stride([2, 2])
                .with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1))
                .with_initializer(hidden.clone())
                .init(device)
        };
        // PyTorch ConvTranspose2d(c_in, c_out, 3, 2, 1, output_padding = 1): n -> 2n.
        let up = |c_in: usize, c_out: usize| {
            ConvTranspose2dConfig::new([c_in, c_out], [3, 3])
                .with_stride([2, 2])
                .with_padding([1, 1])
                .with_padding_out([1, 1])
                .with_initializer(hidden.clone())
                .init(device)
        };
        let bottleneck = e2 * BOTTLENECK_SIDE * BOTTLENECK_SIDE;
        let he = layers.he_init;
        Self {
            project_in: layers
                .projection
                .map(|c| Projection::new(INPUT_CHANNELS, c, &hidden, he, device)),
            down: vec![down(first, e0), down(e0, e1), down(e1, e2)],
            residual: (0..layers.residual_blocks)
                .map(|_| ResidualBlock::new(e2, &hidden, he, device))
                .collect(),
            to_latent: LinearConfig::new(bottleneck, latent)
                .with_initializer(linear.clone())
                .init(device),
            from_latent: LinearConfig::new(latent, bottleneck)
                .with_initializer(hidden.clone())
                .init(device),
            // PyTorch ConvTranspose2d(c_in, c_out, 4, 2, 4): 48 -> (48 - 1) * 2 - 8 + 4 = 90.
            up: vec![
                up(e2, d0),
                up(d0, d1),
                ConvTranspose2dConfig::new([d1, first], [4, 4])
                    .with_stride([2, 2])
                    .with_padding([4, 4])
                    .with_initializer(if layers.projection.is_some() {
                        hidden.clone()
                    } else {
                        linear.clone()
                    })
                    .init(device),
            ],
            project_out: layers
                .projection
                .map(|c| Projection::new(c, INPUT_CHANNELS, &linear, he, device)),
            offset: layers.mean_offset.then(|| zero_offset(device)),
            scale: (layers.standardise == Some(true)).then(|| unit_scale(device)),
            bottleneck_channels: e2,
            latent,
            negative_slope,
            conv: layers.conv,
        }
    }

    /// The same network computing its convolutions with `conv`.
    pub fn with_conv(self, conv: ConvAlgorithm) -> Self {
        Self { conv, ..self }
    }

    /// Encoder f (eq. 2) on centred, masked inputs.
    ///
    /// # Shapes
    /// - centred: `[batch, 540, 90, 90]` -> `[batch, k]`
    pub(crate) fn encode_centred(&self, centred: Tensor<4>) -> Tensor<2> {
        let slope = self.negative_slope;
        let batch = centred.dims()[0];
        let centred = match &self.scale {
            Some(scale) => centred / scale.val().unsqueeze_dim::<4>(0), // [batch, 540, 90, 90]
            None => centred,
        };
        let mut x = match &self.project_in {
            Some(projection) => leaky_relu(projection.forward(centred), slope), // [batch, C, 90, 90]
            None => centred, // [batch, 540, 90, 90]
        };
        for conv in &self.down {
            x = leaky_relu(self.conv.conv2d(conv, x), slope); // [batch, e0, 45, 45], [batch, e1, 23, 23], [batch, e2, 12, 12]
        }
        for block in &self.residual {
            x = block.forward(x, slope, self.conv); // [batch, e2, 12, 12]
        }
        let x = x.reshape([batch, self.bottleneck_channels * BOTTLENECK_SIDE * BOTTLENECK_SIDE]); // [batch, e2*144]
        self.to_latent.forward(x) // [batch, k]
    }

    /// Decoder g (eq. 3) without the offset.
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, 540, 90, 90]`
    pub(crate) fn decode_deviation(&self, latent: Tensor<2>) -> Tensor<4> {
        let slope = self.negative_slope;
        let batch = latent.dims()[0];
        let y = leaky_relu(self.from_latent.forward(latent), slope); // [batch, e2*144]
        let mut y = y.reshape([batch, self.bottleneck_channels, BOTTLENECK_SIDE, BOTTLENECK_SIDE]); // [batch, e2, 12, 12]
        let last = self.up.len().saturating_sub(1);
        for (i, deconv) in self.up.iter().enumerate() {
            y = self.conv.conv_transpose2d(deconv, y); // [batch, d0, 24, 24], [batch, d1, 48, 48], [batch, C or 540, 90, 90]
            if i < last {
                y = leaky_relu(y, slope);
            }
        }
        let y = match &self.project_out {
            Some(projection) => projection.forward(leaky_relu(y, slope)), // [batch, 540, 90, 90]
            None => y,
        };
        debug_assert_eq!(y.dims()[1..], [INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
        match &self.scale {
            Some(scale) => y * scale.val().unsqueeze_dim::<4>(0), // [batch, 540, 90, 90]
            None => y,
        }
    }
}

/// A residual block of §3.2 ([HZRS16]): two 3x3 convolutions, a leaky ReLU and a skip.
#[derive(Module, Debug)]
pub struct ResidualBlock {
    pub(super) conv1: Conv2d,
    pub(super) conv2: Conv2d,
}

impl ResidualBlock {
    /// With `zero_second`, the second convolution starts at zero: the block is an identity
    /// (then a leaky ReLU) until training moves it.
    fn new(channels: usize, init: &Initializer, zero_second: bool, device: &Device) -> Self {
        let conv = |init: Initializer| {
            Conv2dConfig::new([channels, channels], [3, 3])
                .with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1))
                .with_initializer(init)
                .init(device)
        };
        let second = if zero_second { Initializer::Zeros } else { init.clone() };
        Self { conv1: conv(init.clone()), conv2: conv(second) }
    }

    /// `act(x + conv2(act(conv1(x))))`.
    ///
    /// # Shapes
    /// - x: `[batch, c, 12, 12]` -> `[batch, c, 12, 12]`
    fn forward(&self, x: Tensor<4>, slope: f64, conv: ConvAlgorithm) -> Tensor<4> {
        let y = leaky_relu(conv.conv2d(&self.conv1, x.clone()), slope); // [batch, c, 12, 12]
        leaky_relu(x + conv.conv2d(&self.conv2, y), slope) // [batch, c, 12, 12]
    }
}

/// A per-pixel linear map of channels (a 1x1 convolution), computed as one matrix product per
/// BRDF, which Burn's CPU backends run several times faster than a 1x1 `Conv2d`.
#[derive(Module, Debug)]
pub struct Projection {
    /// `[c_out, c_in]`
    weight: Param<Tensor<2>>,
    /// `[c_out]`
    bias: Param<Tensor<1>>,
}

impl Projection {
    /// Weights from `init` (fan-in `c_in`); the bias zero with `zero_bias`, else uniform in
    /// +-1/sqrt(c_in) as PyTorch's `Conv2d` does.
    fn new(
        c_in: usize,
        c_out: usize,
        init: &Initializer,
        zero_bias: bool,
        device: &Device,
    ) -> Self {
        let bound = 1.0 / (c_in as f64).sqrt();
        let bias = if zero_bias {
            Tensor::zeros([c_out], device)
        } else {
            Tensor::random([c_out], Distribution::Uniform(-bound, bound), device)
        };
        Self {
            weight: init.init_with([c_out, c_in], Some(c_in), Some(c_out), device),
            bias: Param::from_tensor(bias),
        }
    }

    /// # Shapes
    /// - x: `[batch, c_in, h, w]` -> `[batch, c_out, h, w]`
    fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let [batch, c_in, h, w] = x.dims();
        let c_out = self.bias.dims()[0];
        let x = x.reshape([batch, c_in, h * w]); // [batch, c_in, h*w]
        let y = self.weight.val().unsqueeze_dim::<3>(0).matmul(x); // [batch, c_out, h*w]
        let y = y + self.bias.val().reshape([1, c_out, 1]); // [batch, c_out, h*w]
        y.reshape([batch, c_out, h, w]) // [batch, c_out, h, w]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::TensorData;

    #[test]
    fn the_projection_gradient_sums_over_the_batch() {
        // d/dW sum(P(x) * g) = sum over batch and pixels of g[b, o, p] * x[b, i, p].
        let device = Device::default().autodiff();
        let init = Initializer::Normal { mean: 0.0, std: 1.0 };
        let proj =
            crate::seeded::with_seed(1, &device, || Projection::new(4, 3, &init, true, &device));
        let xs: Vec<f32> = (0..2 * 4 * 6).map(|i| ((i * 7 % 13) as f32 - 6.0) / 5.0).collect();
        let gs: Vec<f32> = (0..2 * 3 * 6).map(|i| ((i * 5 % 11) as f32 - 5.0) / 4.0).collect();
        let x = Tensor::<4>::from_data(TensorData::new(xs.clone(), [2, 4, 2, 3]), &device);
        let g = Tensor::<4>::from_data(TensorData::new(gs.clone(), [2, 3, 2, 3]), &device);
        let grads = (proj.forward(x) * g).sum().backward();
        let got: Vec<f32> = proj.weight.grad(&grads).unwrap().into_data().try_into_vec().unwrap();
        for o in 0..3 {
            for i in 0..4 {
                let expected: f32 = (0..2)
                    .flat_map(|b| (0..6).map(move |p| (b, p)))
                    .map(|(b, p)| gs[(b * 3 + o) * 6 + p] * xs[(b * 4 + i) * 6 + p])
                    .sum();
                let value = got[o * 4 + i];
                assert!((value - expected).abs() < 1e-4, "dW[{o},{i}] = {value}, not {expected}");
            }
        }
    }
}

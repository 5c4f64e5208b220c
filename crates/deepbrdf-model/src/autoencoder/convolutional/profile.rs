//! A per-layer profile of Table 1's network (§3.2): for each convolution, residual
//! convolution, fully connected layer and deconvolution, the seconds of its forward pass, of
//! its input gradient and of its weight gradient on a batch, with the multiply-adds each does,
//! so that the layers that dominate a training step, and how far each runs from the
//! machine's matrix-product rate, can be read off.
//!
//! Each pass is timed as the network computes it (the configuration's [`ConvAlgorithm`]):
//! the forward pass alone (plus the product with a fixed output gradient and its sum, which
//! every timing includes), then forward and backward with only the input tracked, then with
//! only the layer's parameters tracked; a gradient's time is the difference from the forward
//! pass's.

use std::time::Instant;

use burn::module::Module;
use burn::nn::conv::{Conv2d, ConvTranspose2d};
use burn::nn::Linear;
use burn::prelude::*;
use burn::tensor::Distribution;

use super::config::ConvAlgorithm;
use super::network::BOTTLENECK_SIDE;
use crate::autoencoder::{Architecture, AutoencoderConfig};
use crate::error::{ModelError, Result};
use deepbrdf_data::layout::{SIDE, SLICE_CHANNELS};

/// The timing of one layer on one batch: medians of the repeated runs, in seconds.
#[derive(Debug, Clone)]
pub struct LayerTiming {
    /// The layer, as Table 1 names it (`conv1`, `res2.b`, `fc_in`, `deconv3`, ...).
    pub name: String,
    /// Input and output shapes, without the batch.
    pub input: Vec<usize>,
    pub output: Vec<usize>,
    /// Multiply-adds of one pass (forward, input gradient or weight gradient: the same
    /// count) over the whole batch.
    pub macs: f64,
    pub forward: f64,
    pub input_gradient: f64,
    pub weight_gradient: f64,
}

impl LayerTiming {
    /// Seconds of forward, input gradient and weight gradient together.
    pub fn total(&self) -> f64 {
        self.forward + self.input_gradient + self.weight_gradient
    }

    /// GFLOP/s (two flops a multiply-add) of a pass that took `seconds`.
    pub fn gflops(&self, seconds: f64) -> f64 {
        2.0 * self.macs / seconds.max(1e-12) / 1e9
    }
}

/// One layer of the network, borrowed.
enum Layer<'a> {
    Conv(&'a Conv2d),
    Deconv(&'a ConvTranspose2d),
    Linear(&'a Linear),
}

/// Profiles every layer of the convolutional network of `config` (initialised with seed 0)
/// on batches of `batch` random inputs, each pass timed `repeats` times after a warm-up.
/// Errors for a slice network, a projection (not a Table 1 layer) or an empty batch.
pub fn profile(
    config: &AutoencoderConfig,
    batch: usize,
    repeats: usize,
    device: &Device,
) -> Result<Vec<LayerTiming>> {
    let Architecture::Convolutional(layers) = &config.architecture else {
        return Err(ModelError::Invalid("the layer profile is for a convolutional network".into()));
    };
    if layers.projection.is_some() || batch == 0 || batch > 256 {
        return Err(ModelError::Invalid(
            "the layer profile needs Table 1's layers (no projection) and 1 to 256 BRDFs".into(),
        ));
    }
    let device = device.clone().autodiff();
    let network = match config.init_seeded(0, &device)? {
        crate::Autoencoder::Convolutional(c) => c,
        _ => unreachable!("a convolutional configuration builds a convolutional network"),
    };
    let algorithm = network.conv;
    let mut out = Vec::new();
    let mut side = SIDE;
    let mut channels = SLICE_CHANNELS;
    for (i, conv) in network.down.iter().enumerate() {
        let timing = time_layer(
            format!("conv{}", i + 1),
            Layer::Conv(conv),
            algorithm,
            [batch, channels, side, side],
            repeats,
            &device,
        )?;
        channels = timing.output[0];
        side = timing.output[1];
        out.push(timing);
    }
    for (i, block) in network.residual.iter().enumerate() {
        for (part, conv) in [("a", &block.conv1), ("b", &block.conv2)] {
            let name = format!("res{}.{part}", i + 1);
            let shape = [batch, channels, side, side];
            out.push(time_layer(name, Layer::Conv(conv), algorithm, shape, repeats, &device)?);
        }
    }
    let bottleneck = channels * BOTTLENECK_SIDE * BOTTLENECK_SIDE;
    let to_latent = Layer::Linear(&network.to_latent);
    out.push(time_layer(
        "fc_in".into(),
        to_latent,
        algorithm,
        [batch, bottleneck, 1, 1],
        repeats,
        &device,
    )?);
    let latent = network.latent;
    let from_latent = Layer::Linear(&network.from_latent);
    out.push(time_layer(
        "fc_out".into(),
        from_latent,
        algorithm,
        [batch, latent, 1, 1],
        repeats,
        &device,
    )?);
    let mut side = BOTTLENECK_SIDE;
    for (i, deconv) in network.up.iter().enumerate() {
        let shape = [batch, channels, side, side];
        let timing = time_layer(
            format!("deconv{}", i + 1),
            Layer::Deconv(deconv),
            algorithm,
            shape,
            repeats,
            &device,
        )?;
        channels = timing.output[0];
        side = timing.output[1];
        out.push(timing);
    }
    Ok(out)
}

impl Layer<'_> {
    /// The layer's output on `x` (`[batch, n, 1, 1]` for a linear layer of n inputs).
    fn forward(&self, algorithm: ConvAlgorithm, x: Tensor<4>) -> Tensor<4> {
        match self {
            Self::Conv(c) => algorithm.conv2d(c, x),
            Self::Deconv(d) => algorithm.conv_transpose2d(d, x),
            Self::Linear(l) => {
                let [b, n, _, _] = x.dims();
                let y = l.forward(x.reshape([b, n])); // [b, m]
                let m = y.dims()[1];
                y.reshape([b, m, 1, 1])
            }
        }
    }

    /// The same layer with no parameter tracked.
    fn untracked(&self) -> Owned {
        match self {
            Self::Conv(c) => Owned::Conv((*c).clone().no_grad()),
            Self::Deconv(d) => Owned::Deconv((*d).clone().no_grad()),
            Self::Linear(l) => Owned::Linear((*l).clone().no_grad()),
        }
    }

    /// Multiply-adds of one forward pass producing `output` (per sample, batch first).
    fn macs(&self, input: &[usize; 4], output: &[usize]) -> f64 {
        let out: usize = output.iter().product();
        let per_output = match self {
            Self::Conv(c) => {
                let [_, c_in, kh, kw] = c.weight.dims();
                c_in * kh * kw
            }
            // Each output pixel takes on average kh*kw / (sh*sw) taps of each input channel.
            Self::Deconv(d) => {
                let [c_in, _, kh, kw] = d.weight.dims();
                return (out * c_in * kh * kw) as f64 / (d.stride[0] * d.stride[1]) as f64;
            }
            Self::Linear(_) => input[1],
        };
        (out * per_output) as f64
    }
}

/// A layer owned (with its parameters untracked).
enum Owned {
    Conv(Conv2d),
    Deconv(ConvTranspose2d),
    Linear(Linear),
}

impl Owned {
    fn layer(&self) -> Layer<'_> {
        match self {
            Self::Conv(c) => Layer::Conv(c),
            Self::Deconv(d) => Layer::Deconv(d),
            Self::Linear(l) => Layer::Linear(l),
        }
    }
}

/// Times the three passes of `layer` on a random input of `shape`.
fn time_layer(
    name: String,
    layer: Layer<'_>,
    algorithm: ConvAlgorithm,
    shape: [usize; 4],
    repeats: usize,
    device: &Device,
) -> Result<LayerTiming> {
    let x = Tensor::<4>::random(shape, Distribution::Uniform(-1.0, 1.0), device);
    let untracked = layer.untracked();
    let probe = untracked.layer().forward(algorithm, x.clone());
    let output = probe.dims();
    let g = Tensor::<4>::random(output, Distribution::Uniform(-1.0, 1.0), device);
    // Every run: forward, the product with g, its sum read back; `tracked` picks what the
    // backward pass (if any) differentiates.
    let run = |layer: &Layer<'_>, track_input: bool, backward: bool| -> Result<f64> {
        let x = if track_input { x.clone().require_grad() } else { x.clone() };
        let start = Instant::now();
        let loss = (layer.forward(algorithm, x) * g.clone()).sum();
        if backward {
            std::hint::black_box(loss.backward());
        } else {
            std::hint::black_box(loss.into_scalar::<f32>());
        }
        device.sync().map_err(|e| ModelError::Invalid(format!("device error: {e:?}")))?;
        Ok(start.elapsed().as_secs_f64())
    };
    let median = |f: &dyn Fn() -> Result<f64>| -> Result<f64> {
        f()?;
        let mut runs = (0..repeats.max(1)).map(|_| f()).collect::<Result<Vec<f64>>>()?;
        runs.sort_by(f64::total_cmp);
        Ok(runs[runs.len() / 2])
    };
    let forward = median(&|| run(&untracked.layer(), false, false))?;
    let with_input = median(&|| run(&untracked.layer(), true, true))?;
    let with_weight = median(&|| run(&layer, false, true))?;
    Ok(LayerTiming {
        name,
        input: shape[1..].to_vec(),
        output: output[1..].to_vec(),
        macs: layer.macs(&shape, &output[1..]) * shape[0] as f64,
        forward,
        input_gradient: (with_input - forward).max(0.0),
        weight_gradient: (with_weight - forward).max(0.0),
    })
}

/// The rate of one square f32 matrix product of side `n` on `device` (GFLOP/s, median of
/// `repeats` after a warm-up): the ceiling the layers' products are measured against.
pub fn matmul_gflops(n: usize, repeats: usize, device: &Device) -> Result<f64> {
    let device = device.clone().without_autodiff();
    let a = Tensor::<2>::random([n, n], Distribution::Uniform(-1.0, 1.0), &device);
    let b = Tensor::<2>::random([n, n], Distribution::Uniform(-1.0, 1.0), &device);
    let mut runs = Vec::new();
    for i in 0..=repeats.max(1) {
        let start = Instant::now();
        let c = a.clone().matmul(b.clone());
        std::hint::black_box(c.slice([0..1, 0..1]).into_scalar::<f32>());
        device.sync().map_err(|e| ModelError::Invalid(format!("device error: {e:?}")))?;
        if i > 0 {
            runs.push(start.elapsed().as_secs_f64());
        }
    }
    runs.sort_by(f64::total_cmp);
    Ok(2.0 * (n as f64).powi(3) / runs[runs.len() / 2] / 1e9)
}

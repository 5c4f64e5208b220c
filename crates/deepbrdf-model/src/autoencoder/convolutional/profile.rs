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
    // Each layer with its name, in the order a forward pass runs them; the input shape of
    // each is the output shape of the one before (the linear layers see [batch, n, 1, 1]).
    let mut layers: Vec<(String, Layer<'_>)> = Vec::new();
    for (i, conv) in network.down.iter().enumerate() {
        layers.push((format!("conv{}", i + 1), Layer::Conv(conv)));
    }
    for (i, block) in network.residual.iter().enumerate() {
        layers.push((format!("res{}.a", i + 1), Layer::Conv(&block.conv1)));
        layers.push((format!("res{}.b", i + 1), Layer::Conv(&block.conv2)));
    }
    layers.push(("fc_in".into(), Layer::Linear(&network.to_latent)));
    layers.push(("fc_out".into(), Layer::Linear(&network.from_latent)));
    for (i, deconv) in network.up.iter().enumerate() {
        layers.push((format!("deconv{}", i + 1), Layer::Deconv(deconv)));
    }
    let mut shape = [batch, SLICE_CHANNELS, SIDE, SIDE];
    let mut out = Vec::new();
    for (name, layer) in layers {
        if matches!(layer, Layer::Linear(_)) {
            shape = [batch, shape[1] * shape[2] * shape[3], 1, 1];
        } else if shape[2] == 1 {
            // After the fully connected layers: the bottleneck images again.
            let channels = shape[1] / (BOTTLENECK_SIDE * BOTTLENECK_SIDE);
            shape = [batch, channels, BOTTLENECK_SIDE, BOTTLENECK_SIDE];
        }
        let timing = time_layer(name, layer, algorithm, shape, repeats, &device)?;
        shape = [batch, timing.output[0], timing.output[1], timing.output[2]];
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
    // Every run: forward, the product with g, its sum read back or differentiated (what the
    // backward pass differentiates: the input if tracked, the layer's parameters if tracked).
    let run = |layer: &Layer<'_>, track_input: bool, backward: bool| -> Result<f64> {
        let timing = crate::timing::timed(repeats, || {
            let x = if track_input { x.clone().require_grad() } else { x.clone() };
            let loss = (layer.forward(algorithm, x) * g.clone()).sum();
            if backward {
                std::hint::black_box(loss.backward());
            } else {
                std::hint::black_box(loss.into_scalar::<f32>());
            }
            device.sync().map_err(|e| ModelError::Invalid(format!("device error: {e:?}")))
        })?;
        Ok(timing.median())
    };
    let forward = run(&untracked.layer(), false, false)?;
    let with_input = run(&untracked.layer(), true, true)?;
    let with_weight = run(&layer, false, true)?;
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
    let timing = crate::timing::timed(repeats, || {
        let c = a.clone().matmul(b.clone());
        std::hint::black_box(c.slice([0..1, 0..1]).into_scalar::<f32>());
        device.sync().map_err(|e| ModelError::Invalid(format!("device error: {e:?}")))
    })?;
    Ok(2.0 * (n as f64).powi(3) / timing.median() / 1e9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autoencoder::ConvolutionalConfig;

    #[test]
    fn every_layer_is_profiled_with_its_shapes_and_work() {
        let config = AutoencoderConfig::convolutional(
            3,
            ConvolutionalConfig::new()
                .with_encoder_channels([2, 2, 2])
                .with_residual_blocks(1)
                .with_decoder_channels([2, 2]),
        );
        let layers = profile(&config, 1, 1, &Device::default()).unwrap();
        let names: Vec<&str> = layers.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "conv1", "conv2", "conv3", "res1.a", "res1.b", "fc_in", "fc_out", "deconv1",
                "deconv2", "deconv3"
            ]
        );
        assert_eq!(
            (layers[0].input.clone(), layers[0].output.clone()),
            (vec![540, 90, 90], vec![2, 45, 45])
        );
        assert_eq!(layers[5].input, vec![2 * 144, 1, 1]);
        assert_eq!(layers[7].input, vec![2, 12, 12]);
        assert_eq!(layers[9].output, vec![540, 90, 90]);
        // conv1: 2 x 45 x 45 outputs of 540 x 9 taps; deconv3: 540 x 90 x 90 outputs of 2 x 16 / 4.
        assert_eq!(layers[0].macs, (2 * 45 * 45 * 540 * 9) as f64);
        assert_eq!(layers[9].macs, (540 * 90 * 90 * 2 * 4) as f64);
        assert!(layers.iter().all(|l| l.forward > 0.0 && l.total() >= l.forward));
        let slice = AutoencoderConfig::slice(3);
        assert!(profile(&slice, 1, 1, &Device::default()).is_err());
    }
}

//! Tests of the convolutions as matrix products ([`super::gemm`]) against Burn's own modules:
//! outputs and input, weight and bias gradients at Table 1's spatial shapes (few channels) and
//! at other strides, kernels and paddings, and a whole training step of a narrow Table 1, on
//! every compiled backend.

use burn::module::{ModuleVisitor, Param};
use burn::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d, ConvTranspose2dConfig};
use burn::nn::{Initializer, PaddingConfig2d};
use burn::prelude::*;

use super::config::ConvAlgorithm;
use super::gemm;
use crate::autoencoder::{Autoencoder, AutoencoderConfig, ConvolutionalConfig, INPUT_SIDE};
use crate::device::DeviceKind;
use crate::loss::LossNorm;
use crate::training_set::TrainingSet;

/// The compiled backends: flex and ndarray, and wgpu in a build with it (on a machine without
/// a GPU, Mesa's lavapipe runs CubeCL's kernels: the operations the GPU runs, checked here).
fn devices() -> Vec<(DeviceKind, Device)> {
    DeviceKind::available()
        .into_iter()
        .filter(|k| matches!(k, DeviceKind::Flex | DeviceKind::Ndarray | DeviceKind::Wgpu))
        .map(|k| (k, k.device().unwrap()))
        .collect()
}

/// Deterministic values in (0.1, 1) that vary with every index (no symmetry to hide a
/// misplaced tap). Positive, like BRDF values and their errors, so that sums over thousands
/// of pixels (the weight gradients) do not cancel down to their f32 rounding.
fn wavy<const D: usize>(shape: [usize; D], phase: f32, device: &Device) -> Tensor<D> {
    let n: usize = shape.iter().product();
    let values: Vec<f32> =
        (0..n).map(|i| 0.55 + 0.45 * ((i as f32 * 0.7311 + phase).sin() * 1.3).tanh()).collect();
    Tensor::from_data(TensorData::new(values, shape), device)
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_to_vec::<f32>().unwrap()
}

/// `max |a - b| <= tol * max |b|`, with what was compared in the message.
fn assert_close(what: &str, a: &[f32], b: &[f32], tol: f32) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    let scale = b.iter().fold(0f32, |m, v| m.max(v.abs()));
    let worst = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0f32, f32::max);
    assert!(scale > 0.0, "{what}: the reference is all zeros");
    assert!(worst <= tol * scale, "{what}: max difference {worst} against scale {scale}");
}

/// The output and the gradients of `sum(y * g)` with respect to x, the weight and the bias.
struct Pass {
    y: Vec<f32>,
    dx: Vec<f32>,
    dw: Vec<f32>,
    db: Vec<f32>,
}

fn pass(
    x: &Tensor<4>,
    weight: &Param<Tensor<4>>,
    bias: Option<&Param<Tensor<1>>>,
    forward: impl Fn(Tensor<4>) -> Tensor<4>,
    g_phase: f32,
) -> Pass {
    let x = x.clone().require_grad();
    let y = forward(x.clone());
    let g = wavy(y.dims(), g_phase, &y.device());
    let grads = (y.clone() * g).sum().backward();
    Pass {
        y: values(y),
        dx: values(x.grad(&grads).expect("x's gradient")),
        dw: values(weight.grad(&grads).expect("the weight's gradient")),
        db: values(bias.expect("a bias").grad(&grads).expect("the bias's gradient")),
    }
}

fn compare(what: &str, gemm: Pass, direct: Pass) {
    assert_close(&format!("{what}: output"), &gemm.y, &direct.y, 1e-5);
    assert_close(&format!("{what}: input gradient"), &gemm.dx, &direct.dx, 1e-5);
    assert_close(&format!("{what}: weight gradient"), &gemm.dw, &direct.dw, 1e-5);
    assert_close(&format!("{what}: bias gradient"), &gemm.db, &direct.db, 1e-5);
}

fn init() -> Initializer {
    Initializer::Uniform { min: -0.5, max: 0.5 }
}

/// A layer under test: its parameters, Burn's own forward and the matrix-product one.
trait Layer: Module {
    fn weight(&self) -> &Param<Tensor<4>>;
    fn bias(&self) -> Option<&Param<Tensor<1>>>;
    fn direct(&self, x: Tensor<4>) -> Tensor<4>;
    fn gemm(&self, x: Tensor<4>) -> Tensor<4>;
}

impl Layer for Conv2d {
    fn weight(&self) -> &Param<Tensor<4>> {
        &self.weight
    }
    fn bias(&self) -> Option<&Param<Tensor<1>>> {
        self.bias.as_ref()
    }
    fn direct(&self, x: Tensor<4>) -> Tensor<4> {
        self.forward(x)
    }
    fn gemm(&self, x: Tensor<4>) -> Tensor<4> {
        gemm::conv2d(self, x)
    }
}

impl Layer for ConvTranspose2d {
    fn weight(&self) -> &Param<Tensor<4>> {
        &self.weight
    }
    fn bias(&self) -> Option<&Param<Tensor<1>>> {
        self.bias.as_ref()
    }
    fn direct(&self, x: Tensor<4>) -> Tensor<4> {
        self.forward(x)
    }
    fn gemm(&self, x: Tensor<4>) -> Tensor<4> {
        gemm::conv_transpose2d(self, x)
    }
}

/// The layer `build` makes, run both ways on every CPU backend; `out`: the output's
/// `[channels, height, width]` where the test states it.
fn check<L: Layer>(
    what: &str,
    build: impl Fn(&Device) -> L,
    input: [usize; 4],
    out: Option<[usize; 3]>,
) {
    for (kind, device) in devices() {
        let device = device.autodiff();
        let layer = crate::seeded::with_seed(3, &device, || build(&device));
        let x = wavy(input, 0.4, &device);
        let what = format!("{kind} {what} on {input:?}");
        let direct = pass(&x, layer.weight(), layer.bias(), |x| layer.direct(x), 1.9);
        let gemm = pass(&x, layer.weight(), layer.bias(), |x| layer.gemm(x), 1.9);
        if let Some([c, h, w]) = out {
            assert_eq!(direct.y.len(), input[0] * c * h * w, "{what}: output size");
        }
        compare(&what, gemm, direct);
    }
}

fn check_conv(config: Conv2dConfig, input: [usize; 4], out: Option<[usize; 2]>) {
    let build = |device: &Device| config.clone().with_initializer(init()).init(device);
    let out = out.map(|[h, w]| [config.channels[1], h, w]);
    check(&format!("conv {config:?}"), build, input, out);
}

fn check_deconv(config: ConvTranspose2dConfig, input: [usize; 4], out: Option<[usize; 2]>) {
    let build = |device: &Device| config.clone().with_initializer(init()).init(device);
    let out = out.map(|[h, w]| [config.channels[1], h, w]);
    check(&format!("deconv {config:?}"), build, input, out);
}

#[test]
fn table1s_strided_convolutions_equal_burns() {
    // 3x3, stride 2, padding 1: 90 -> 45 -> 23 -> 12 (Table 1's encoder).
    let down = |c: [usize; 2]| {
        Conv2dConfig::new(c, [3, 3])
            .with_stride([2, 2])
            .with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1))
    };
    check_conv(down([3, 2]), [2, 3, 90, 90], Some([45, 45]));
    check_conv(down([2, 3]), [2, 2, 45, 45], Some([23, 23]));
    check_conv(down([3, 2]), [2, 3, 23, 23], Some([12, 12]));
}

#[test]
fn table1s_residual_convolutions_equal_burns() {
    let same =
        Conv2dConfig::new([3, 3], [3, 3]).with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1));
    check_conv(same, [2, 3, 12, 12], Some([12, 12]));
}

#[test]
fn table1s_transposed_convolutions_equal_burns() {
    // 3x3, stride 2, padding 1, output padding 1: 12 -> 24 -> 48; 4x4, stride 2, padding 4:
    // 48 -> 90 (Table 1's decoder).
    let up = |c: [usize; 2]| {
        ConvTranspose2dConfig::new(c, [3, 3])
            .with_stride([2, 2])
            .with_padding([1, 1])
            .with_padding_out([1, 1])
    };
    check_deconv(up([3, 2]), [2, 3, 12, 12], Some([24, 24]));
    check_deconv(up([2, 3]), [2, 2, 24, 24], Some([48, 48]));
    let last = ConvTranspose2dConfig::new([3, 2], [4, 4]).with_stride([2, 2]).with_padding([4, 4]);
    check_deconv(last, [2, 3, 48, 48], Some([90, 90]));
}

#[test]
fn other_kernels_strides_and_paddings_equal_burns() {
    // Rectangular kernels, unequal strides, asymmetric and no padding.
    let conv = Conv2dConfig::new([2, 3], [2, 3])
        .with_stride([3, 1])
        .with_padding(PaddingConfig2d::Explicit(0, 2, 1, 0));
    check_conv(conv, [1, 2, 11, 7], None);
    let valid = Conv2dConfig::new([2, 2], [5, 1]).with_stride([2, 2]);
    check_conv(valid, [3, 2, 9, 6], None);
    // Phases whose windows start before the input and outputs that are not a multiple of the
    // stride.
    let deconv = ConvTranspose2dConfig::new([2, 3], [5, 2])
        .with_stride([3, 2])
        .with_padding([1, 0])
        .with_padding_out([2, 1]);
    check_deconv(deconv, [2, 2, 4, 5], None);
    let plain = ConvTranspose2dConfig::new([3, 2], [3, 3]);
    check_deconv(plain, [1, 3, 5, 4], None);
}

#[test]
fn batches_split_to_keep_buffers_small_give_the_same_result() {
    let device = devices()[0].1.clone();
    let x = wavy([5, 2, 3, 3], 0.1, &device);
    let f = |t: Tensor<4>| {
        let b = t.dims()[0];
        t.reshape([b, 2, 9]) * 2.0
    };
    let whole = gemm::in_chunks_of(x.clone(), 5, f);
    let split = gemm::in_chunks_of(x.clone(), 2, f);
    assert_eq!(split.dims(), [5, 2, 9]);
    assert_eq!(values(whole), values(split));
    // A sample larger than the limit still runs, one at a time.
    let one = gemm::in_chunks(x, usize::MAX, f);
    assert_eq!(one.dims(), [5, 2, 9]);
}

/// Collects every float parameter's gradient, in visiting order.
struct Gradients<'a> {
    grads: &'a burn::optim::GradientsParams,
    out: Vec<Vec<f32>>,
}

impl ModuleVisitor for Gradients<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(g) = self.grads.get::<D>(param.id) {
            self.out.push(values(g));
        }
    }
}

#[test]
fn a_training_step_of_a_narrow_table1_equals_the_direct_one() {
    // Table 1's strides, kernels and paddings, 3 channels a layer, 2 residual blocks; the loss
    // and every parameter's gradient of one batch of 2, through the training step itself.
    let layers = ConvolutionalConfig::new()
        .with_projection(Some(3))
        .with_encoder_channels([3, 3, 3])
        .with_residual_blocks(2)
        .with_decoder_channels([3, 3]);
    let config = AutoencoderConfig::convolutional(2, layers);
    let set = layouts(2);
    for (kind, device) in devices() {
        let device = device.autodiff();
        let model = config.init_seeded(11, &device).unwrap();
        let step = |conv: ConvAlgorithm| {
            let Autoencoder::Convolutional(c) = model.clone() else { unreachable!() };
            let model = Autoencoder::Convolutional(c.with_conv(conv));
            let (loss, grads) =
                super::step::gradients(&model, &set, &[0, 1], None, None, 1, LossNorm::L2, &device);
            let mut visitor = Gradients { grads: &grads.grads[0].0, out: Vec::new() };
            model.visit(&mut visitor);
            (loss, visitor.out)
        };
        let (direct_loss, direct) = step(ConvAlgorithm::Direct);
        let (gemm_loss, gemm) = step(ConvAlgorithm::Gemm);
        assert!(
            ((gemm_loss - direct_loss) / direct_loss).abs() < 1e-5,
            "{kind}: loss {gemm_loss} vs {direct_loss}"
        );
        assert!(direct.len() > 20, "{kind}: {} gradients", direct.len());
        assert_eq!(gemm.len(), direct.len());
        // Each gradient within 1e-5 of its own largest value, or of 1e-4 of the step's largest
        // gradient where a parameter's is smaller than that (there it is f32 round-off: one
        // bias's gradient sums to ~1e-9 from terms of ~1e-3).
        let largest = direct.iter().flatten().fold(0f32, |m, v| m.max(v.abs()));
        for (i, (g, d)) in gemm.iter().zip(&direct).enumerate() {
            let own = d.iter().fold(0f32, |m, v| m.max(v.abs()));
            let worst = g.iter().zip(d).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
            let scale = own.max(1e-4 * largest);
            assert!(worst <= 1e-5 * scale, "{kind}: parameter {i}: {worst} against {scale}");
        }
    }
}

/// Two smooth layouts with a masked corner.
fn layouts(n: usize) -> TrainingSet {
    let values = crate::autoencoder::INPUT_VALUES;
    let (mut inputs, mut masks) = (Vec::new(), Vec::new());
    for b in 0..n {
        let input: Vec<f32> = (0..values)
            .map(|i| {
                let (row, col, ch) =
                    ((i / INPUT_SIDE) % INPUT_SIDE, i % INPUT_SIDE, i / (INPUT_SIDE * INPUT_SIDE));
                0.3 * b as f32 + (row as f32 * 0.05 + ch as f32 * 0.011).sin() - 0.004 * col as f32
            })
            .collect();
        let mask: Vec<f32> = (0..values)
            .map(|i| if (i / INPUT_SIDE) % INPUT_SIDE + i % INPUT_SIDE < 160 { 1.0 } else { 0.0 })
            .collect();
        inputs.push(input);
        masks.push(mask);
    }
    let names = (0..n).map(|b| format!("layout-{b}")).collect();
    TrainingSet::from_layouts("layouts", names, inputs, masks).unwrap()
}

//! Table 1's convolutions as matrix products (im2col): the same [`Conv2d`] and
//! [`ConvTranspose2d`] modules, the same parameters and the same values as their own `forward`,
//! computed as pad once, shifted (strided) slices stacked into columns, then one batched matrix
//! product. Burn's GPU backends without kernel autotuning run every convolution pass, forward
//! and both gradients, as a direct convolution kernel; a matrix product is the operation GPUs
//! (and BLAS) run fastest, and autodiff turns the slices' and the product's gradients into
//! matrix products and copies too (docs/gpu.md).
//!
//! A transposed convolution of stride s is computed by its s x s sub-pixel phases
//! (Shi et al. 2016): output pixel `s * m + r` is an ordinary convolution of the input at
//! offsets `m + d`, with the kernel taps `k = r + p - s * d` that fall inside the kernel. All
//! phases share one window of offsets, so one product with a weight matrix holding every
//! phase's taps (zero where a phase has no tap) gives all of them; Table 1's last
//! deconvolution (4 x 4, stride 2, padding 4) uses every tap of that window, the 3 x 3 ones
//! 9 of 16. No buffer grows with the kernel's overlap, as col2im's does.

use burn::module::Param;
use burn::nn::conv::{Conv2d, ConvTranspose2d};
use burn::nn::PaddingConfig2d;
use burn::prelude::*;
use burn::tensor::s;

use super::config::ConvAlgorithm;

impl ConvAlgorithm {
    /// `conv.forward(x)`, computed by this algorithm.
    pub(crate) fn conv2d(self, conv: &Conv2d, x: Tensor<4>) -> Tensor<4> {
        match self {
            Self::Direct => conv.forward(x),
            Self::Gemm => conv2d(conv, x),
        }
    }

    /// `deconv.forward(x)`, computed by this algorithm.
    pub(crate) fn conv_transpose2d(self, deconv: &ConvTranspose2d, x: Tensor<4>) -> Tensor<4> {
        match self {
            Self::Direct => deconv.forward(x),
            Self::Gemm => conv_transpose2d(deconv, x),
        }
    }
}

/// The largest column or output buffer built in one product, in f32 values (1 GiB): larger
/// batches are split, as a wgpu storage binding holds at most 2 GiB.
const MAX_BUFFER_VALUES: usize = 1 << 28;

/// `conv.forward(x)` as a matrix product; a layer this lowering does not cover (groups,
/// dilation or `Same` padding, none of which Table 1 uses) runs Burn's own forward.
///
/// # Shapes
/// - x: `[batch, c_in, h, w]` -> `[batch, c_out, h_out, w_out]`
pub(crate) fn conv2d(conv: &Conv2d, x: Tensor<4>) -> Tensor<4> {
    let [batch, c_in, h, w] = x.dims();
    let [c_out, _, kh, kw] = conv.weight.dims();
    let [sh, sw] = conv.stride;
    let ((top, bottom), (left, right)) = match &conv.padding {
        PaddingConfig2d::Valid => ((0, 0), (0, 0)),
        PaddingConfig2d::Explicit(t, l, b, r) => ((*t, *b), (*l, *r)),
        PaddingConfig2d::Same => return conv.forward(x),
    };
    let (hp, wp) = (h + top + bottom, w + left + right);
    if conv.groups != 1 || conv.dilation != [1, 1] || hp < kh || wp < kw || sh * sw == 0 {
        return conv.forward(x);
    }
    let (ho, wo) = ((hp - kh) / sh + 1, (wp - kw) / sw + 1);
    let taps = kh * kw;
    let weight = conv.weight.val().reshape([1, c_out, c_in * taps]); // [1, c_out, c_in*kh*kw]
    let padded = pad(x, top, bottom, left, right); // [batch, c_in, hp, wp]
    let (tap_rows, tap_cols): (Vec<usize>, Vec<usize>) = ((0..kh).collect(), (0..kw).collect());
    let per_sample = (c_in * taps).max(c_out) * ho * wo;
    let y = in_chunks(padded, per_sample, |x| {
        let columns = columns(x, &tap_rows, &tap_cols, [ho, wo], [sh, sw]); // [b, c_in*kh*kw, ho*wo]
        weight.clone().matmul(columns) // [b, c_out, ho*wo]
    });
    let y = y.reshape([batch, c_out, ho, wo]); // [batch, c_out, ho, wo]
    with_bias(y, conv.bias.as_ref())
}

/// `deconv.forward(x)` as one matrix product over the sub-pixel phases; a layer this lowering
/// does not cover (groups or dilation, which Table 1 does not use) runs Burn's own forward.
///
/// # Shapes
/// - x: `[batch, c_in, h, w]` -> `[batch, c_out, h_out, w_out]`
pub(crate) fn conv_transpose2d(deconv: &ConvTranspose2d, x: Tensor<4>) -> Tensor<4> {
    let [batch, c_in, h, w] = x.dims();
    let [_, c_out, kh, kw] = deconv.weight.dims();
    let phases = |axis: usize, n: usize, k: usize| {
        Phases::new(n, k, deconv.stride[axis], deconv.padding[axis], deconv.padding_out[axis])
    };
    let (Some(rows), Some(cols)) = (phases(0, h, kh), phases(1, w, kw)) else {
        return deconv.forward(x);
    };
    if deconv.groups != 1 || deconv.dilation != [1, 1] {
        return deconv.forward(x);
    }
    let (dh, dw) = (rows.offsets(), cols.offsets());
    let (mh, mw) = (rows.per_phase, cols.per_phase);
    let phases = rows.stride * cols.stride;
    let window = dh * dw;

    // The weight of every phase and offset: [c_out * phases, c_in * window], zero where the
    // phase has no tap at that offset (index kh*kw of the kernel with a zero appended).
    let kernel = deconv.weight.val().reshape([c_in, c_out, kh * kw]); // [c_in, c_out, kh*kw]
    let zero = Tensor::<3>::zeros([c_in, c_out, 1], &kernel.device());
    let kernel = Tensor::cat(vec![kernel, zero], 2); // [c_in, c_out, kh*kw + 1]
    let mut taps = Vec::with_capacity(phases * window);
    for ry in 0..rows.stride {
        for rx in 0..cols.stride {
            for oy in 0..dh {
                for ox in 0..dw {
                    taps.push(match (rows.tap(ry, oy), cols.tap(rx, ox)) {
                        (Some(ky), Some(kx)) => (ky * kw + kx) as i64,
                        _ => (kh * kw) as i64,
                    });
                }
            }
        }
    }
    let taps =
        Tensor::<1, Int>::from_data(TensorData::new(taps, [phases * window]), &kernel.device());
    let weight = kernel
        .select(2, taps) // [c_in, c_out, phases*window]
        .reshape([c_in, c_out * phases, window])
        .swap_dims(0, 1) // [c_out*phases, c_in, window]
        .reshape([1, c_out * phases, c_in * window]); // [1, c_out*phases, c_in*window]

    let padded = pad(x, rows.before, rows.after, cols.before, cols.after); // [batch, c_in, ., .]
    let window_rows: Vec<usize> = (0..dh).map(|i| rows.start(i)).collect();
    let window_cols: Vec<usize> = (0..dw).map(|j| cols.start(j)).collect();
    let per_sample = (c_in * window).max(c_out * phases) * mh * mw;
    let y = in_chunks(padded, per_sample, |x| {
        let columns = columns(x, &window_rows, &window_cols, [mh, mw], [1, 1]); // [b, c_in*window, mh*mw]
        weight.clone().matmul(columns) // [b, c_out*phases, mh*mw]
    });
    let y = y
        .reshape([batch, c_out, rows.stride, cols.stride, mh, mw])
        .permute([0, 1, 4, 2, 5, 3]) // [batch, c_out, mh, sy, mw, sx]
        .reshape([batch, c_out, mh * rows.stride, mw * cols.stride]);
    let y = y.slice(s![.., .., 0..rows.out, 0..cols.out]); // [batch, c_out, h_out, w_out]
    with_bias(y, deconv.bias.as_ref())
}

/// The sub-pixel phases of a transposed convolution along one axis: output `stride * m + r`
/// takes input `m + d` through kernel tap `r + padding - stride * d`, for the offsets d of one
/// window shared by all phases.
struct Phases {
    stride: usize,
    padding: usize,
    kernel: usize,
    /// Output length.
    out: usize,
    /// Outputs per phase (`ceil(out / stride)`; the last phases' extra ones are cropped).
    per_phase: usize,
    /// The window's first and last offsets d (every d with `s * d` in
    /// `padding - kernel + 1 ..= stride - 1 + padding`).
    first: isize,
    last: isize,
    /// Zeros before and after the input so every offset of every output is inside it.
    before: usize,
    after: usize,
}

impl Phases {
    fn new(
        n: usize,
        kernel: usize,
        stride: usize,
        padding: usize,
        padding_out: usize,
    ) -> Option<Self> {
        if stride == 0 || kernel == 0 {
            return None;
        }
        let full = n.checked_sub(1)? * stride + kernel + padding_out;
        let out = full.checked_sub(2 * padding).filter(|&o| o > 0)?;
        let per_phase = out.div_ceil(stride);
        let (s, p, k) = (stride as isize, padding as isize, kernel as isize);
        let first = -(k - 1 - p).div_euclid(s); // ceil((p - k + 1) / s)
        let last = (s - 1 + p).div_euclid(s);
        let before = usize::try_from(-first).unwrap_or(0);
        let read = per_phase as isize - 1 + last; // the largest input index read
        let after = usize::try_from(read - (n as isize - 1)).unwrap_or(0);
        Some(Self { stride, padding, kernel, out, per_phase, first, last, before, after })
    }

    /// Number of offsets in the window.
    fn offsets(&self) -> usize {
        (self.last - self.first + 1) as usize
    }

    /// Where the window's `index`-th offset starts in the padded input.
    fn start(&self, index: usize) -> usize {
        (self.first + self.before as isize) as usize + index
    }

    /// The kernel tap of phase `r` at the window's `index`-th offset, if it has one.
    fn tap(&self, r: usize, index: usize) -> Option<usize> {
        let d = self.first + index as isize;
        let k = r as isize + self.padding as isize - self.stride as isize * d;
        usize::try_from(k).ok().filter(|&k| k < self.kernel)
    }
}

/// The columns of a convolution over `x`: for each pair of a row start in `rows` and a
/// column start in `cols`, the `size` pixels from there `stride` apart, stacked after each
/// channel's (the order of a `[c_out, c_in, kh, kw]` weight flattened).
///
/// # Shapes
/// - x: `[b, c_in, h, w]` -> `[b, c_in * rows * cols, size[0] * size[1]]`
fn columns(
    x: Tensor<4>,
    rows: &[usize],
    cols: &[usize],
    size: [usize; 2],
    stride: [usize; 2],
) -> Tensor<3> {
    let [b, c_in, _, _] = x.dims();
    let ([h, w], [sh, sw]) = (size, stride);
    let shifted: Vec<Tensor<4>> = rows
        .iter()
        .flat_map(|&i| cols.iter().map(move |&j| (i, j)))
        .map(|(i, j)| {
            x.clone().slice(s![.., .., i..i + sh * (h - 1) + 1;sh, j..j + sw * (w - 1) + 1;sw])
        })
        .collect(); // each [b, c_in, h, w]
    Tensor::stack::<5>(shifted, 2).reshape([b, c_in * rows.len() * cols.len(), h * w])
}

/// Zero padding of the last two axes (top, bottom, left, right); none is a no-op.
fn pad(x: Tensor<4>, top: usize, bottom: usize, left: usize, right: usize) -> Tensor<4> {
    if top + bottom + left + right == 0 {
        return x;
    }
    x.pad([(top, bottom), (left, right)], burn::tensor::ops::PadMode::Constant(0.0))
}

/// `f` over the batch in chunks whose buffers (`per_sample` values a sample) stay under
/// [`MAX_BUFFER_VALUES`], concatenated.
pub(super) fn in_chunks(
    x: Tensor<4>,
    per_sample: usize,
    f: impl Fn(Tensor<4>) -> Tensor<3>,
) -> Tensor<3> {
    let chunk = (MAX_BUFFER_VALUES / per_sample.max(1)).max(1);
    in_chunks_of(x, chunk, f)
}

/// `f` over the batch in chunks of `chunk` samples (the last one shorter), concatenated.
pub(super) fn in_chunks_of(
    x: Tensor<4>,
    chunk: usize,
    f: impl Fn(Tensor<4>) -> Tensor<3>,
) -> Tensor<3> {
    let batch = x.dims()[0];
    let chunk = chunk.max(1);
    if chunk >= batch {
        return f(x);
    }
    let parts: Vec<Tensor<3>> = (0..batch)
        .step_by(chunk)
        .map(|start| f(x.clone().narrow(0, start, chunk.min(batch - start))))
        .collect();
    Tensor::cat(parts, 0)
}

fn with_bias(y: Tensor<4>, bias: Option<&Param<Tensor<1>>>) -> Tensor<4> {
    match bias {
        Some(b) => {
            let c = b.dims()[0];
            y + b.val().reshape([1, c, 1, 1])
        }
        None => y,
    }
}

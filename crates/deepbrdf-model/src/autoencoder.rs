//! The DeepBRDF autoencoder (Hu et al., CGF 2020, §3.2, Table 1) and its CPU-sized variant.
//!
//! The input is one BRDF in the §3.2 layout: 540 channels (phi_d x rgb) of 90 x 90 images
//! (rows theta_h, columns theta_d), values in the eq. (1) mapped space. Invalid cells are zeroed
//! at the input (§3.2, footnote †), so the encoder takes the validity mask with the values.
//!
//! [`AutoencoderConfig::paper`] is Table 1 exactly: three 3x3 stride-2 convolutions
//! (540 -> 256 -> 128 -> 64 channels, 90 -> 45 -> 23 -> 12 pixels), three residual blocks at
//! 64 x 12 x 12, FC to k, FC back to 64 x 12 x 12 and three deconvolutions to 128 x 24 x 24,
//! 256 x 48 x 48 and 540 x 90 x 90 (the last 4x4), with the paddings of the PyTorch reference
//! (`shared/bench/torch_table1.py`).
//!
//! [`AutoencoderConfig::cpu`] keeps that shape but works on a per-pixel projection of the 540
//! slice channels: a 1x1 convolution 540 -> C at 90 x 90 first and C -> 540 last, with narrow
//! layers in between, and predicts deviations from the per-value training mean (a fixed,
//! non-trained offset). See the README for why and what it costs.

use burn::module::Param;
use burn::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d, ConvTranspose2dConfig};
use burn::nn::{Initializer, Linear, LinearConfig, PaddingConfig2d};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;
use burn::tensor::{Distribution, TensorData};

use crate::compact::CompactBasis;
use crate::error::ModelError;
use crate::spectral::SpectralPath;

/// Channels of the §3.2 layout: 180 phi_d slices x 3 colour channels.
pub const INPUT_CHANNELS: usize = 540;
/// Side of each layout image (90 theta_h rows x 90 theta_d columns).
pub const INPUT_SIDE: usize = 90;
/// Values of one BRDF in the layout (`540 * 90 * 90`, the MERL table's value count).
pub const INPUT_VALUES: usize = INPUT_CHANNELS * INPUT_SIDE * INPUT_SIDE;
/// Side of the bottleneck images after three stride-2 convolutions (90 -> 45 -> 23 -> 12).
pub const BOTTLENECK_SIDE: usize = 12;
/// K of the `cpu` preset's spectral path: 96 principal directions of the training set (100
/// materials span 99; with 48 the 51 left out still carried 6e-4 of mapped-space MSE, above what
/// nearest-slice filling loses from 1/9 of the slices). The basis is stored in the model:
/// 96 x 4.37 M values, 1.7 GB in f32 while training, 0.67 GB as saved ([`crate::compact`]).
pub const CPU_SPECTRAL_BASIS: usize = 96;
/// Width of the `cpu` preset's coefficient-space MLPs.
pub const CPU_SPECTRAL_HIDDEN: usize = 256;

/// Architecture of the autoencoder. `k` ([`latent`](Self::latent)) is the FC-10 of Table 1.
#[derive(Config, Debug, PartialEq)]
pub struct AutoencoderConfig {
    /// k, the dimension of the latent vector (Table 1's FC-10; §3.2 studies 5 to 40).
    #[config(default = 10)]
    pub latent: usize,
    /// Width C of a per-pixel 1x1 projection 540 -> C applied first (and C -> 540 applied
    /// last); `None` in Table 1, where the strided convolutions see all 540 channels.
    #[config(default = "None")]
    pub projection: Option<usize>,
    /// Output channels of the three 3x3 stride-2 convolutions (Table 1: 256, 128, 64).
    #[config(default = "[256, 128, 64]")]
    pub encoder_channels: [usize; 3],
    /// Number of residual blocks at the bottleneck (Table 1: 3).
    #[config(default = 3)]
    pub residual_blocks: usize,
    /// Output channels of the first two deconvolutions (Table 1: 128 at 24 x 24, 256 at 48 x 48).
    #[config(default = "[128, 256]")]
    pub decoder_channels: [usize; 2],
    /// Negative slope of the leaky ReLUs (PyTorch's default, as the paper does not say).
    #[config(default = 0.01)]
    pub negative_slope: f64,
    /// Predict deviations from a fixed per-value offset (the training mean in mapped space,
    /// set with [`Autoencoder::with_offset`]); the input is centred on it too. Not in Table 1.
    #[config(default = false)]
    pub mean_offset: bool,
    /// He initialisation (normal, gain sqrt(2) for the leaky ReLUs, the residual blocks'
    /// second convolutions at zero so they start as identities) instead of PyTorch's default
    /// (uniform, gain 1/sqrt(3)), under which activations shrink layer after layer and the
    /// latent vector starts near zero. Not a Table 1 setting; training converges much faster.
    #[config(default = false)]
    pub he_init: bool,
    /// Whether the convolutional encoder and decoder of Table 1 are present (they are in
    /// both presets of the paper's network; the `cpu` preset replaces them by the spectral
    /// path).
    #[config(default = true)]
    pub convolutional: bool,
    /// K, the directions of a spectral path (see [`crate::spectral`]; set with
    /// [`Autoencoder::with_basis`]): the K leading principal directions of the training set,
    /// K >= k. Needs `mean_offset`. Not in Table 1.
    #[config(default = "None")]
    pub spectral_basis: Option<usize>,
    /// Width of the spectral path's two coefficient-space MLPs (none: a purely linear path).
    #[config(default = "None")]
    pub spectral_hidden: Option<usize>,
}

impl AutoencoderConfig {
    /// Table 1 exactly, with latent dimension `k`.
    pub fn paper(k: usize) -> Self {
        Self::new().with_latent(k)
    }

    /// The CPU preset: the autoencoder on spectral coordinates ([`crate::spectral`]): the
    /// input projected on the training set's [`CPU_SPECTRAL_BASIS`] leading principal
    /// directions (eq. (1) space, centred on the training mean), MLP encoder and decoder of
    /// width [`CPU_SPECTRAL_HIDDEN`] to and from k, output expanded back to 540 x 90 x 90.
    /// Not Table 1: on a 2-core CPU the convolutional network cannot leave the training mean
    /// within the 30-minute budget of `sweep-k` (measured: 18 epochs of a narrow variant,
    /// 2.5 min, mapped MSE 0.061 against PCA's 0.011 at k = 10), while this trains 1000 epochs
    /// in seconds. The convolutional layer widths are kept for reference but unused.
    pub fn cpu(k: usize) -> Self {
        Self::new()
            .with_latent(k)
            .with_projection(Some(24))
            .with_encoder_channels([32, 48, 64])
            .with_residual_blocks(2)
            .with_decoder_channels([48, 32])
            .with_mean_offset(true)
            .with_he_init(true)
            .with_convolutional(false)
            .with_spectral_basis(Some(CPU_SPECTRAL_BASIS))
            .with_spectral_hidden(Some(CPU_SPECTRAL_HIDDEN))
    }

    /// A spectral-only network ([`crate::spectral`]): latent dimension `k`, `size` principal
    /// directions, coefficient-space MLPs of width `hidden` (none: linear), the mean offset, no
    /// convolutions. [`cpu`](Self::cpu) is one, with sizes chosen for the MERL collection.
    pub fn spectral(k: usize, size: usize, hidden: Option<usize>) -> Self {
        Self::new()
            .with_latent(k)
            .with_mean_offset(true)
            .with_convolutional(false)
            .with_spectral_basis(Some(size))
            .with_spectral_hidden(hidden)
    }

    /// Whether training can run on the spectral coefficients alone (no convolutions).
    pub fn spectral_only(&self) -> bool {
        !self.convolutional && self.spectral_basis.is_some()
    }

    /// The initializer of hidden layers (followed by a leaky ReLU) and of linear outputs.
    fn initializers(&self) -> (Initializer, Initializer) {
        if self.he_init {
            let gain = (2.0 / (1.0 + self.negative_slope * self.negative_slope)).sqrt();
            (
                Initializer::KaimingNormal { gain, fan_out_only: false },
                Initializer::KaimingNormal { gain: 1.0, fan_out_only: false },
            )
        } else {
            let default =
                Initializer::KaimingUniform { gain: 1.0 / 3f64.sqrt(), fan_out_only: false };
            (default.clone(), default)
        }
    }

    /// Checks the sizes once, so [`init`](Self::init) cannot build a degenerate network.
    pub fn validate(&self) -> crate::error::Result<()> {
        let widths = self
            .encoder_channels
            .iter()
            .chain(self.decoder_channels.iter())
            .chain(self.projection.iter());
        if self.latent == 0 || self.latent > 4096 {
            return Err(ModelError::Invalid(format!(
                "latent dimension k = {} is out of range (1 to 4096)",
                self.latent
            )));
        }
        if let Some(w) = widths.into_iter().find(|&&w| w == 0 || w > 4096) {
            return Err(ModelError::Invalid(format!("a layer width of {w} is out of range")));
        }
        if self.residual_blocks > 64 {
            return Err(ModelError::Invalid(format!(
                "{} residual blocks is out of range (0 to 64)",
                self.residual_blocks
            )));
        }
        if let Some(size) = self.spectral_basis {
            if !self.mean_offset {
                return Err(ModelError::Invalid("a spectral path needs the mean offset".into()));
            }
            if size < self.latent || size > 4096 {
                return Err(ModelError::Invalid(format!(
                    "a spectral basis of {size} directions for k = {} (need k to 4096)",
                    self.latent
                )));
            }
        } else if !self.convolutional {
            return Err(ModelError::Invalid(
                "without convolutions the network needs a spectral path".into(),
            ));
        }
        if self.spectral_hidden.is_some_and(|h| h == 0 || h > 4096) {
            return Err(ModelError::Invalid("a spectral MLP width is out of range".into()));
        }
        if !self.negative_slope.is_finite() {
            return Err(ModelError::Invalid("the leaky ReLU slope must be finite".into()));
        }
        Ok(())
    }

    /// [`init`](Self::init) with the weights drawn from `seed`, reproducibly.
    ///
    /// Burn draws initial weights from one random generator per device, shared by the whole
    /// process: two models initialised at once (two trainings in one process, as in the test
    /// suite) would interleave their draws. Seeding and drawing therefore happen under one
    /// process-wide lock.
    pub fn init_seeded(&self, seed: u64, device: &Device) -> crate::error::Result<Autoencoder> {
        static INIT: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let _guard = INIT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        device.seed(seed);
        self.init(device)
    }

    /// Builds the network on `device` with freshly initialised weights (and a zero offset).
    pub fn init(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.build(device, true)
    }

    /// [`init`](Self::init) without the spectral path's basis (`K x 540 x 90 x 90` values),
    /// for loading the weights of a model whose basis is stored apart ([`crate::compact`]).
    pub(crate) fn init_without_basis(&self, device: &Device) -> crate::error::Result<Autoencoder> {
        self.build(device, false)
    }

    fn build(&self, device: &Device, allocate_basis: bool) -> crate::error::Result<Autoencoder> {
        self.validate()?;
        let [e0, e1, e2] = self.encoder_channels;
        let [d0, d1] = self.decoder_channels;
        let first = self.projection.unwrap_or(INPUT_CHANNELS);
        let (hidden, linear) = self.initializers();
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
        let conv = self.convolutional;
        let model = Autoencoder {
            project_in: self
                .projection
                .filter(|_| conv)
                .map(|c| Projection::new(INPUT_CHANNELS, c, &hidden, self.he_init, device)),
            down: match conv {
                true => vec![down(first, e0), down(e0, e1), down(e1, e2)],
                false => Vec::new(),
            },
            residual: (0..if conv { self.residual_blocks } else { 0 })
                .map(|_| ResidualBlock::new(e2, &hidden, self.he_init, device))
                .collect(),
            to_latent: conv.then(|| {
                LinearConfig::new(bottleneck, self.latent)
                    .with_initializer(linear.clone())
                    .init(device)
            }),
            from_latent: conv.then(|| {
                LinearConfig::new(self.latent, bottleneck)
                    .with_initializer(hidden.clone())
                    .init(device)
            }),
            // PyTorch ConvTranspose2d(c_in, c_out, 4, 2, 4): 48 -> (48 - 1) * 2 - 8 + 4 = 90.
            up: match conv {
                true => vec![
                    up(e2, d0),
                    up(d0, d1),
                    ConvTranspose2dConfig::new([d1, first], [4, 4])
                        .with_stride([2, 2])
                        .with_padding([4, 4])
                        .with_initializer(if self.projection.is_some() {
                            hidden.clone()
                        } else {
                            linear.clone()
                        })
                        .init(device),
                ],
                false => Vec::new(),
            },
            project_out: self
                .projection
                .filter(|_| conv)
                .map(|c| Projection::new(c, INPUT_CHANNELS, &linear, self.he_init, device)),
            offset: self.mean_offset.then(|| {
                Param::from_tensor(Tensor::zeros([INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], device))
                    .set_require_grad(false)
            }),
            spectral: self.spectral_basis.map(|size| {
                SpectralPath::new(
                    size,
                    self.latent,
                    self.spectral_hidden,
                    &hidden,
                    self.negative_slope,
                    allocate_basis,
                    device,
                )
            }),
            bottleneck_channels: e2,
            latent: self.latent,
            negative_slope: self.negative_slope,
        };
        // Burn initialises parameters lazily, on first use, from the device's random generator;
        // drawing them all now, in a fixed order, keeps a seeded run reproducible even when the
        // first use happens in parallel training shards.
        let _ = model.clone().into_record();
        Ok(model)
    }
}

/// A residual block of §3.2 ([HZRS16]): two 3x3 convolutions, a leaky ReLU and a skip.
#[derive(Module, Debug)]
pub struct ResidualBlock {
    conv1: Conv2d,
    conv2: Conv2d,
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
    fn forward(&self, x: Tensor<4>, slope: f64) -> Tensor<4> {
        let y = leaky_relu(self.conv1.forward(x.clone()), slope); // [batch, c, 12, 12]
        leaky_relu(x + self.conv2.forward(y), slope) // [batch, c, 12, 12]
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

/// The autoencoder of §3.2: encoder f (eq. 2) and decoder g (eq. 3).
#[derive(Module, Debug)]
pub struct Autoencoder {
    project_in: Option<Projection>,
    down: Vec<Conv2d>,
    residual: Vec<ResidualBlock>,
    to_latent: Option<Linear>,
    from_latent: Option<Linear>,
    up: Vec<ConvTranspose2d>,
    project_out: Option<Projection>,
    /// Fixed per-value offset (the training mean in mapped space), not trained.
    offset: Option<Param<Tensor<3>>>,
    /// The spectral path of the `cpu` preset.
    spectral: Option<SpectralPath>,
    bottleneck_channels: usize,
    latent: usize,
    negative_slope: f64,
}

impl Autoencoder {
    /// Sets the fixed output offset (the per-value training mean, 540 x 90 x 90 in layout order).
    /// Errors if the configuration has no offset or `values` has the wrong length.
    pub fn with_offset(mut self, values: &[f32]) -> crate::error::Result<Self> {
        let Some(param) = self.offset.take() else {
            return Err(ModelError::Invalid("this configuration has no mean offset".into()));
        };
        if values.len() != INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "an offset has {INPUT_VALUES} values, got {}",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("offset value {i} is not finite")));
        }
        let data = TensorData::new(values.to_vec(), [INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
        let param = param.map(|old| Tensor::from_data(data, &old.device()));
        self.offset = Some(param.set_require_grad(false));
        Ok(self)
    }

    /// Sets the spectral path's basis: K orthonormal rows of `540 * 90 * 90` values in layout
    /// order ([`crate::principal::fit_basis`]).
    pub fn with_basis(mut self, rows: &[f32]) -> crate::error::Result<Self> {
        let Some(path) = self.spectral.take() else {
            return Err(ModelError::Invalid("this configuration has no spectral path".into()));
        };
        self.spectral = Some(path.with_basis(rows)?);
        Ok(self)
    }

    /// The spectral path, if the configuration has one.
    pub fn spectral(&self) -> Option<&SpectralPath> {
        self.spectral.as_ref()
    }

    /// Moves the spectral path's basis out ([`SpectralPath::take_basis`]) as a
    /// [`CompactBasis`] around the offset; the network can then no longer encode or decode by
    /// itself, only run the coordinate-space MLPs.
    pub(crate) fn take_compact_basis(&mut self) -> crate::error::Result<CompactBasis> {
        let path = self
            .spectral
            .as_mut()
            .ok_or_else(|| ModelError::Invalid("this configuration has no spectral path".into()))?;
        let size = path.size();
        let rows = path.take_basis()?;
        let offset = self
            .offset()
            .ok_or_else(|| ModelError::Invalid("a spectral network without its offset".into()))?;
        CompactBasis::new(&rows, size, &offset)
    }

    /// The latent dimension k.
    pub fn latent(&self) -> usize {
        self.latent
    }

    /// Encoder f (eq. 2): the k latent values of each BRDF. Invalid cells are zeroed first.
    ///
    /// # Shapes
    /// - input: `[batch, 540, 90, 90]` mapped values
    /// - mask: `[batch, 540, 90, 90]`, 1 for valid cells, 0 for invalid ones
    /// - output: `[batch, k]`
    pub fn encode(&self, input: Tensor<4>, mask: Tensor<4>) -> Tensor<2> {
        let centred = match &self.offset {
            Some(offset) => (input - offset.val().unsqueeze_dim::<4>(0)) * mask, // [batch, 540, 90, 90]
            None => input * mask, // [batch, 540, 90, 90]
        };
        self.encode_centred(centred)
    }

    /// The encoder on inputs already centred and masked: `(input - offset) * mask` (just
    /// `input * mask` without an offset). Training prepares these on the CPU.
    ///
    /// # Shapes
    /// - centred: `[batch, 540, 90, 90]`
    /// - output: `[batch, k]`
    pub fn encode_centred(&self, centred: Tensor<4>) -> Tensor<2> {
        let slope = self.negative_slope;
        let batch = centred.dims()[0];
        let spectral = self.spectral.as_ref().map(|path| {
            let flat = centred.clone().reshape([batch, INPUT_VALUES]); // [batch, 540*90*90]
            path.encode(path.coefficients(flat)) // [batch, k]
        });
        let Some(to_latent) = &self.to_latent else {
            // Validation guarantees a spectral path when there are no convolutions.
            return spectral
                .unwrap_or_else(|| Tensor::zeros([batch, self.latent], &centred.device()));
        };
        let mut x = match &self.project_in {
            Some(projection) => leaky_relu(projection.forward(centred), slope), // [batch, C, 90, 90]
            None => centred, // [batch, 540, 90, 90]
        };
        for conv in &self.down {
            x = leaky_relu(conv.forward(x), slope); // [batch, e0, 45, 45], [batch, e1, 23, 23], [batch, e2, 12, 12]
        }
        for block in &self.residual {
            x = block.forward(x, slope); // [batch, e2, 12, 12]
        }
        let x = x.reshape([batch, self.bottleneck_channels * BOTTLENECK_SIDE * BOTTLENECK_SIDE]); // [batch, e2*144]
        let z = to_latent.forward(x); // [batch, k]
        match spectral {
            Some(spectral) => z + spectral, // [batch, k]
            None => z,
        }
    }

    /// Decoder g (eq. 3): the mapped BRDF of each latent vector.
    ///
    /// # Shapes
    /// - latent: `[batch, k]`
    /// - output: `[batch, 540, 90, 90]` mapped values (invalid cells are meaningless)
    pub fn decode(&self, latent: Tensor<2>) -> Tensor<4> {
        let y = self.decode_deviation(latent); // [batch, 540, 90, 90]
        match &self.offset {
            Some(offset) => y + offset.val().unsqueeze_dim::<4>(0), // [batch, 540, 90, 90]
            None => y,
        }
    }

    /// The decoder without the fixed offset: the deviation from it (the whole output when the
    /// configuration has no offset). Training compares this with centred targets.
    ///
    /// # Shapes
    /// - latent: `[batch, k]`
    /// - output: `[batch, 540, 90, 90]`
    pub fn decode_deviation(&self, latent: Tensor<2>) -> Tensor<4> {
        let slope = self.negative_slope;
        let batch = latent.dims()[0];
        let shape = [batch, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
        let linear = self.spectral.as_ref().map(|path| {
            path.expand(path.decode(latent.clone())).reshape(shape) // [batch, 540, 90, 90]
        });
        let Some(from_latent) = &self.from_latent else {
            return linear.unwrap_or_else(|| Tensor::zeros(shape, &latent.device()));
        };
        let y = leaky_relu(from_latent.forward(latent), slope); // [batch, e2*144]
        let mut y = y.reshape([batch, self.bottleneck_channels, BOTTLENECK_SIDE, BOTTLENECK_SIDE]); // [batch, e2, 12, 12]
        let last = self.up.len().saturating_sub(1);
        for (i, deconv) in self.up.iter().enumerate() {
            y = deconv.forward(y); // [batch, d0, 24, 24], [batch, d1, 48, 48], [batch, C or 540, 90, 90]
            if i < last {
                y = leaky_relu(y, slope);
            }
        }
        let y = match &self.project_out {
            Some(projection) => projection.forward(leaky_relu(y, slope)), // [batch, 540, 90, 90]
            None => y,
        };
        match linear {
            Some(linear) => y + linear, // [batch, 540, 90, 90]
            None => y,
        }
    }

    /// The fixed offset, if the configuration has one (540 x 90 x 90 values, layout order).
    pub fn offset(&self) -> Option<Vec<f32>> {
        self.offset.as_ref().and_then(|p| p.val().into_data().try_into_vec().ok())
    }

    /// g(f(x)): the reconstruction the loss of eq. (4) compares with the input.
    ///
    /// # Shapes
    /// - input, mask: `[batch, 540, 90, 90]`
    /// - output: `[batch, 540, 90, 90]`
    pub fn forward(&self, input: Tensor<4>, mask: Tensor<4>) -> Tensor<4> {
        let latent = self.encode(input, mask); // [batch, k]
        self.decode(latent) // [batch, 540, 90, 90]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device() -> Device {
        Device::default()
    }

    #[test]
    fn the_projection_gradient_sums_over_the_batch() {
        // d/dW sum(P(x) * g) = sum over batch and pixels of g[b, o, p] * x[b, i, p].
        let device = device().autodiff();
        let proj =
            Projection::new(4, 3, &Initializer::Normal { mean: 0.0, std: 1.0 }, true, &device);
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

    #[test]
    fn presets_validate_and_differ_only_where_documented() {
        let paper = AutoencoderConfig::paper(10);
        assert_eq!(paper.encoder_channels, [256, 128, 64]);
        assert_eq!(paper.decoder_channels, [128, 256]);
        assert_eq!(paper.residual_blocks, 3);
        assert_eq!(paper.projection, None);
        assert!(!paper.mean_offset);
        paper.validate().unwrap();
        AutoencoderConfig::cpu(40).validate().unwrap();
        assert!(AutoencoderConfig::paper(0).validate().is_err());
        assert!(AutoencoderConfig::cpu(10).with_projection(Some(0)).validate().is_err());
    }

    #[test]
    fn shapes_follow_table_1_with_a_narrow_network() {
        // Same strides, kernels and paddings as Table 1, narrow widths to stay fast.
        let config = AutoencoderConfig::new()
            .with_latent(3)
            .with_projection(Some(2))
            .with_encoder_channels([2, 2, 2])
            .with_residual_blocks(1)
            .with_decoder_channels([2, 2])
            .with_mean_offset(true);
        let model = config.init(&device()).unwrap();
        assert_eq!(model.latent(), 3);
        let x = Tensor::<4>::ones([1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], &device());
        let z = model.encode(x.clone(), x.clone());
        assert_eq!(z.dims(), [1, 3]);
        let y = model.decode(z);
        assert_eq!(y.dims(), [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
    }

    #[test]
    fn a_fresh_spectral_network_is_its_linear_fit() {
        // Three orthonormal directions (disjoint supports) and an offset, k = 2: before
        // training, encode gives the projections on the first two and decode rebuilds the offset
        // plus their combination; the third direction is what k = 2 loses.
        let config = AutoencoderConfig::spectral(2, 3, Some(4));
        assert!(config.clone().with_mean_offset(false).validate().is_err());
        assert!(config.clone().with_spectral_basis(Some(1)).validate().is_err());
        assert!(config.clone().with_spectral_basis(None).validate().is_err());
        let third = INPUT_VALUES / 3;
        let mut basis = vec![0f32; 3 * INPUT_VALUES];
        for j in 0..3 {
            let end = if j == 2 { INPUT_VALUES } else { (j + 1) * third };
            let norm = 1.0 / ((end - j * third) as f32).sqrt();
            basis[j * INPUT_VALUES + j * third..j * INPUT_VALUES + end].fill(norm);
        }
        let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| (i % 13) as f32 / 13.0).collect();
        let model = config.init_seeded(5, &device()).unwrap();
        assert!(model.clone().with_basis(&basis[1..]).is_err());
        let model = model.with_basis(&basis).unwrap().with_offset(&offset).unwrap();
        assert_eq!(model.spectral().map(|p| p.size()), Some(3));
        let (a, b, c) = (3.0f32, -2.0f32, 0.5f32);
        let mix = |c: f32| -> Vec<f32> {
            (0..INPUT_VALUES)
                .map(|i| {
                    offset[i]
                        + a * basis[i]
                        + b * basis[INPUT_VALUES + i]
                        + c * basis[2 * INPUT_VALUES + i]
                })
                .collect()
        };
        let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
        let x = Tensor::<4>::from_data(TensorData::new(mix(c), shape), &device());
        let z: Vec<f32> =
            model.encode(x.clone(), x.ones_like()).into_data().try_into_vec().unwrap();
        assert!((z[0] - a).abs() < 1e-3 && (z[1] - b).abs() < 1e-3, "{z:?}");
        let back = model.decode(Tensor::from_data(TensorData::new(z, [1, 2]), &device()));
        let expected = Tensor::<4>::from_data(TensorData::new(mix(0.0), shape), &device());
        let err: f32 = (back - expected).abs().max().into_scalar();
        assert!(err < 1e-4, "{err}");
    }

    #[test]
    fn offset_is_added_to_the_output_and_rejected_when_absent() {
        let config = AutoencoderConfig::new()
            .with_latent(2)
            .with_projection(Some(1))
            .with_encoder_channels([1, 1, 1])
            .with_residual_blocks(0)
            .with_decoder_channels([1, 1])
            .with_mean_offset(true);
        let model = config.init(&device()).unwrap();
        let z = Tensor::<2>::zeros([1, 2], &device());
        let base: Vec<f32> = model.decode(z.clone()).into_data().try_into_vec().unwrap();
        let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| (i % 7) as f32).collect();
        let model = model.with_offset(&offset).unwrap();
        let shifted: Vec<f32> = model.decode(z).into_data().try_into_vec().unwrap();
        for i in [0, 1, 5, 12345, INPUT_VALUES - 1] {
            assert!((shifted[i] - base[i] - offset[i]).abs() < 1e-5, "value {i}");
        }
        assert!(model.with_offset(&[0.0; 3]).is_err());
        let plain = config.with_mean_offset(false).init(&device()).unwrap();
        assert!(plain.with_offset(&offset).is_err());
    }
}

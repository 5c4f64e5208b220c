//! The `slice` preset's network (not Table 1, but the paper's premise of one network shared
//! across phi_d slices, sized to ship): every one of the 540 (theta_h, theta_d) images of the
//! §3.2 layout is written in one shared basis of M directions ([`super::basis`]), and
//!
//! - encoder f (eq. 2): `a = B x` per image (540 x M coefficients), `c = P (a - m)` (the K
//!   leading principal components of the coefficient vectors), `z = c[..k] + f_mlp(c)`;
//! - decoder g (eq. 3): the coefficients of the image of slice phi_d, colour c are
//!   `m + (P[..k]^T z) + g_mlp(z, phi_d)[c]`, with `g_mlp` ONE MLP shared by all 180 slices
//!   (phi_d enters as the Fourier features `cos(h phi_d), sin(h phi_d)`, h = 1..H), and the
//!   image is `B^T` of them.
//!
//! With cell weights w emphasising the highlight's centre ([`super::basis`]), `B x` is `(w x)
//! S^T` and the image `S^T a`; the coefficients' error is the weighted cells' error.
//!
//! Both MLPs' last layers start at zero: an untrained network is PCA in the mapped space within
//! the slice basis' span. B (M x 8100), m and P (K x 540 M) are fixed, fitted before training
//! (docs/model.md gives the preset's size). There is no per-value offset: B spans the mean
//! shape (it is fitted to uncentred images), m holds it.

use burn::module::Param;
use burn::nn::Linear;
use burn::prelude::*;
use burn::tensor::TensorData;

use deepbrdf_data::layout::{PLANE, SIDE as INPUT_SIDE, SLICE_CHANNELS as INPUT_CHANNELS};

use super::basis::pixel_weights;
use super::config::SliceConfig;
use super::mlp::{mlp_forward, mlp_layers};
use crate::autoencoder::init::initializers;
use crate::error::ModelError;
use deepbrdf_data::merl::N_PHI_D;

/// Colour channels of one phi_d slice.
const COLOURS: usize = INPUT_CHANNELS / N_PHI_D;

/// Slice basis, mean coefficients, principal components and the two MLPs.
#[derive(Module, Debug)]
pub struct SliceNetwork {
    /// `[M, 8100]`: orthonormal rows. Fixed.
    basis: Param<Tensor<2>>,
    /// `[540 * M]`: the training set's mean coefficients. Fixed.
    mean: Param<Tensor<1>>,
    /// `[K, 540 * M]`: orthonormal rows (zero past the training set's rank). Fixed.
    components: Param<Tensor<2>>,
    /// f: K -> hidden -> hidden -> k (empty: none).
    encoder: Vec<Linear>,
    /// g: k + 2H -> hidden -> hidden -> 3 M, shared by the slices (empty: none).
    decoder: Vec<Linear>,
    directions: usize,
    size: usize,
    latent: usize,
    harmonics: usize,
    negative_slope: f64,
    /// The cell weights' emphasis of the highlight's centre ([`super::basis::pixel_weights`]);
    /// 0: an orthonormal basis.
    centre_emphasis: f64,
}

fn fixed<const D: usize>(shape: [usize; D], device: &Device) -> Param<Tensor<D>> {
    Param::from_tensor(Tensor::zeros(shape, device)).set_require_grad(false)
}

impl SliceNetwork {
    /// The network of `layers` for latent dimension `latent` and leaky ReLU slope
    /// `negative_slope`; fixed parts at zero until [`with_fit`](Self::with_fit), the MLPs'
    /// last layers at zero.
    pub(crate) fn new(
        latent: usize,
        negative_slope: f64,
        layers: &SliceConfig,
        device: &Device,
    ) -> Self {
        let (hidden_init, _) = initializers(true, negative_slope);
        let mlp =
            |from: usize, to: usize| mlp_layers(from, layers.hidden, to, &hidden_init, device);
        let (m, size, k) = (layers.directions, layers.components, latent);
        Self {
            basis: fixed([m, PLANE], device),
            mean: fixed([INPUT_CHANNELS * m], device),
            components: fixed([size, INPUT_CHANNELS * m], device),
            encoder: mlp(size, k),
            decoder: mlp(k + 2 * layers.harmonics, COLOURS * m),
            directions: m,
            size,
            latent: k,
            harmonics: layers.harmonics,
            negative_slope,
            centre_emphasis: layers.centre_emphasis.unwrap_or(0.0),
        }
    }

    /// k.
    pub fn latent(&self) -> usize {
        self.latent
    }

    /// M, the slice basis' directions.
    pub fn directions(&self) -> usize {
        self.directions
    }

    /// Coefficient values of one BRDF: 540 x M.
    pub fn coefficient_len(&self) -> usize {
        INPUT_CHANNELS * self.directions
    }

    /// Sets the fixed parts: the slice basis (M x 8100, row-major), the mean coefficients
    /// (540 M) and the principal components (K x 540 M, row-major).
    pub fn with_fit(
        mut self,
        basis: &[f32],
        mean: &[f32],
        components: &[f32],
    ) -> crate::error::Result<Self> {
        let len = self.coefficient_len();
        let sizes = [
            ("slice basis", basis.len(), self.directions * PLANE),
            ("mean coefficients", mean.len(), len),
            ("principal components", components.len(), self.size * len),
        ];
        for (what, got, want) in sizes {
            if got != want {
                return Err(ModelError::Invalid(format!(
                    "{what}: {want} values expected, got {got}"
                )));
            }
        }
        if let Some(i) = basis.iter().chain(mean).chain(components).position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("fitted value {i} is not finite")));
        }
        let set2 = |old: Param<Tensor<2>>, values: &[f32], shape: [usize; 2]| {
            let data = TensorData::new(values.to_vec(), shape);
            old.map(|old| Tensor::from_data(data, &old.device())).set_require_grad(false)
        };
        self.basis = set2(self.basis, basis, [self.directions, PLANE]);
        self.components = set2(self.components, components, [self.size, len]);
        let data = TensorData::new(mean.to_vec(), [len]);
        self.mean =
            self.mean.map(|old| Tensor::from_data(data, &old.device())).set_require_grad(false);
        Ok(self)
    }

    fn mlp(&self, layers: &[Linear], x: Tensor<2>) -> Option<Tensor<2>> {
        mlp_forward(layers, x, self.negative_slope)
    }

    /// The cell weights of the basis ([`super::basis::pixel_weights`]).
    pub fn pixel_weights(&self) -> Vec<f32> {
        pixel_weights(self.centre_emphasis)
    }

    /// `(w x) S^T` for every image (the basis rows S are the synthesis directions, the cell
    /// weights w those of [`super::basis`]).
    ///
    /// # Shapes
    /// - masked: `[batch, 540, 90, 90]` -> `[batch, 540 * M]`
    pub fn coefficients(&self, masked: Tensor<4>) -> Tensor<2> {
        let batch = masked.dims()[0];
        let mut images = masked.reshape([batch * INPUT_CHANNELS, PLANE]); // [batch*540, 8100]
        if self.centre_emphasis != 0.0 {
            let w = TensorData::new(self.pixel_weights(), [1, PLANE]);
            images = images * Tensor::<2>::from_data(w, &self.basis.device());
        }
        let a = images.matmul(self.basis.val().transpose()); // [batch*540, M]
        a.reshape([batch, self.coefficient_len()])
    }

    /// `z = c[..k] + f(c)`, `c = P (a - m)`.
    ///
    /// # Shapes
    /// - coefficients: `[batch, 540 * M]` -> `[batch, k]`
    pub fn encode_coefficients(&self, coefficients: Tensor<2>) -> Tensor<2> {
        let c = self.principal_coordinates(coefficients); // [batch, K]
        let head = self.head(c.clone()); // [batch, k]
        match self.mlp(&self.encoder, c) {
            Some(f) => head + f,
            None => head,
        }
    }

    /// `c = P (a - m)`, the K principal coordinates of the coefficients.
    ///
    /// # Shapes
    /// - coefficients: `[batch, 540 * M]` -> `[batch, K]`
    fn principal_coordinates(&self, coefficients: Tensor<2>) -> Tensor<2> {
        let centred = coefficients - self.mean.val().unsqueeze_dim::<2>(0); // [batch, 540 M]
        centred.matmul(self.components.val().transpose())
    }

    /// `c[..k]`.
    fn head(&self, c: Tensor<2>) -> Tensor<2> {
        let batch = c.dims()[0];
        c.slice([0..batch, 0..self.latent])
    }

    /// The encoder without its MLP, `c[..k]`: the latent of PCA within the basis' span (where
    /// [`crate::refine`] starts besides the encoder's latent).
    ///
    /// # Shapes
    /// - coefficients: `[batch, 540 * M]` -> `[batch, k]`
    pub fn linear_latent(&self, coefficients: Tensor<2>) -> Tensor<2> {
        self.head(self.principal_coordinates(coefficients))
    }

    /// The slice basis' values (the synthesis directions S), `M x 8100` row-major.
    pub fn basis_values(&self) -> crate::error::Result<Vec<f32>> {
        crate::read_back::values(self.basis.val(), "the slice basis")
    }

    /// The Fourier features of the 180 slice centres, phi_d = (p + 1/2) degrees.
    fn slice_features(&self, device: &Device) -> Tensor<2> {
        let h = self.harmonics;
        let mut values = Vec::with_capacity(N_PHI_D * 2 * h);
        for p in 0..N_PHI_D {
            let phi = (p as f64 + 0.5).to_radians();
            for j in 1..=h {
                values.push((j as f64 * phi).cos() as f32);
                values.push((j as f64 * phi).sin() as f32);
            }
        }
        Tensor::from_data(TensorData::new(values, [N_PHI_D, 2 * h]), device)
    }

    /// The linear path of the decoder alone, `m + P[..k]^T z` (PCA within the basis' span).
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, 540 * M]`
    pub fn decode_linear(&self, latent: Tensor<2>) -> Tensor<2> {
        let [_, k] = latent.dims();
        let head = self.components.val().slice([0..k, 0..self.coefficient_len()]); // [k, 540 M]
        latent.matmul(head) + self.mean.val().unsqueeze_dim::<2>(0)
    }

    /// The coefficients of the output: `m + P[..k]^T z + g(z, phi_d)` for each slice.
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, 540 * M]`
    pub fn decode_coefficients(&self, latent: Tensor<2>) -> Tensor<2> {
        let [batch, k] = latent.dims();
        let len = self.coefficient_len();
        let linear = self.decode_linear(latent.clone());
        if self.decoder.is_empty() {
            return linear;
        }
        let device = latent.device();
        let z = latent.unsqueeze_dim::<3>(1).repeat_dim(1, N_PHI_D); // [batch, 180, k]
        let features = self.slice_features(&device).unsqueeze_dim::<3>(0).repeat_dim(0, batch); // [batch, 180, 2H]
        let input =
            Tensor::cat(vec![z, features], 2).reshape([batch * N_PHI_D, k + 2 * self.harmonics]);
        let g = self.mlp(&self.decoder, input).map(|g| g.reshape([batch, len])); // [batch, 540 M]
        match g {
            Some(g) => linear + g,
            None => linear,
        }
    }

    /// `S^T a` for every image.
    ///
    /// # Shapes
    /// - coefficients: `[batch, 540 * M]` -> `[batch, 540, 90, 90]`
    pub fn expand(&self, coefficients: Tensor<2>) -> Tensor<4> {
        let batch = coefficients.dims()[0];
        let a = coefficients.reshape([batch * INPUT_CHANNELS, self.directions]); // [batch*540, M]
        a.matmul(self.basis.val()).reshape([batch, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE])
    }

    /// Encoder f (eq. 2) on masked inputs (invalid cells 0; no offset).
    ///
    /// # Shapes
    /// - masked: `[batch, 540, 90, 90]` -> `[batch, k]`
    pub(crate) fn encode_centred(&self, masked: Tensor<4>) -> Tensor<2> {
        self.encode_coefficients(self.coefficients(masked))
    }

    /// Decoder g (eq. 3): the whole mapped output (there is no separate offset).
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, 540, 90, 90]`
    pub(crate) fn decode_deviation(&self, latent: Tensor<2>) -> Tensor<4> {
        self.expand(self.decode_coefficients(latent))
    }
}

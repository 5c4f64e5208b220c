//! The spectral path of the `cpu` preset (not in the paper): the autoencoder of §3.2 run on the
//! coordinates of a BRDF in the K leading principal directions of the training set (eq. (1)
//! space, centred on the training mean, see [`crate::principal`]).
//!
//! - encoder: `c = U (x - mu)` (K coefficients), `z = c[..k] + f(c)`
//! - decoder: `c_hat = [z, 0] + g(z)`, `x_hat = mu + U^T c_hat`
//!
//! with f, g small MLPs (leaky ReLU) whose last layers start at zero, so an untrained network is
//! the rank-k linear fit (PCA in the mapped space) and training learns the nonlinear part. With
//! K at least the rank of the training set, U^T represents every training BRDF exactly and the
//! loss of eq. (4) on the training set equals the squared error of the coefficients (plus a
//! constant), which is how training computes it: a step costs microseconds instead of the
//! convolutions' ~0.1 s per BRDF on two cores.

use burn::module::Param;
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::leaky_relu;
use burn::tensor::TensorData;

use crate::error::ModelError;
use deepbrdf_data::merl::VALUES as INPUT_VALUES;

/// The fixed basis and the two coefficient-space networks.
#[derive(Module, Debug)]
pub struct SpectralPath {
    /// `[K, 540 * 90 * 90]`: orthonormal rows (zero rows past the training set's rank). Fixed.
    /// `None` once the codec has taken it ([`take_basis`](Self::take_basis)).
    basis: Option<Param<Tensor<2>>>,
    /// f: K -> hidden -> hidden -> k (empty: none).
    encoder: Vec<Linear>,
    /// g: k -> hidden -> hidden -> K (empty: none).
    decoder: Vec<Linear>,
    size: usize,
    latent: usize,
    negative_slope: f64,
}

impl SpectralPath {
    /// A path of `size` directions for latent dimension `latent`, with MLPs of width `hidden`
    /// (none without); hidden layers from `init`, the last ones at zero; the basis at zero
    /// until [`with_basis`](Self::with_basis), or absent without `allocate_basis` (for a codec
    /// that keeps the basis its own way).
    pub(crate) fn new(
        size: usize,
        latent: usize,
        hidden: Option<usize>,
        init: &Initializer,
        negative_slope: f64,
        allocate_basis: bool,
        device: &Device,
    ) -> Self {
        let mlp = |from: usize, to: usize| mlp_layers(from, hidden, to, init, device);
        Self {
            basis: allocate_basis.then(|| {
                Param::from_tensor(Tensor::zeros([size, INPUT_VALUES], device))
                    .set_require_grad(false)
            }),
            encoder: mlp(size, latent),
            decoder: mlp(latent, size),
            size,
            latent,
            negative_slope,
        }
    }

    /// K, the number of directions.
    pub fn size(&self) -> usize {
        self.size
    }

    /// k, the latent dimension.
    pub fn latent(&self) -> usize {
        self.latent
    }

    /// Sets the basis: `size` rows of `540 * 90 * 90` values in layout order, replacing the
    /// path's basis, or on `device` for a path built without one (a network trained afresh
    /// is built without its zero basis: 1.7 GB for the `cpu` preset).
    pub fn with_basis(mut self, rows: Vec<f32>, device: &Device) -> crate::error::Result<Self> {
        if rows.len() != self.size * INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "a basis of {} directions has {} values, got {}",
                self.size,
                self.size * INPUT_VALUES,
                rows.len()
            )));
        }
        if let Some(i) = rows.iter().position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("basis value {i} is not finite")));
        }
        let data = TensorData::new(rows, [self.size, INPUT_VALUES]);
        let param = match self.basis.take() {
            Some(old) => old.map(|old| Tensor::from_data(data, &old.device())),
            None => Param::from_tensor(Tensor::from_data(data, device)),
        };
        self.basis = Some(param.set_require_grad(false));
        Ok(self)
    }

    /// Whether the path holds its basis.
    pub fn has_basis(&self) -> bool {
        self.basis.is_some()
    }

    /// The path without its basis (dropped, not read: a training checkpoint leaves out the
    /// basis that resuming fits again).
    pub(crate) fn without_basis(mut self) -> Self {
        self.basis = None;
        self
    }

    /// Moves the basis out (`K * 540 * 90 * 90` values, row-major), for a codec that stores
    /// it its own way ([`crate::compact`]); afterwards only [`encode`](Self::encode) and
    /// [`decode`](Self::decode), the coordinate-space networks, are usable.
    pub fn take_basis(&mut self) -> crate::error::Result<Vec<f32>> {
        let basis = self.basis.take().ok_or_else(taken)?;
        // The parameter is consumed: a network holding the only reference gives its buffer
        // up without a copy.
        crate::read_back::values(basis.into_value(), "the spectral basis")
    }

    fn basis(&self) -> Tensor<2> {
        // Only `DeepBrdf` takes the basis, and it never projects or expands with the network.
        self.basis.as_ref().map(|b| b.val()).expect("the spectral basis was taken by a codec")
    }

    fn mlp(&self, layers: &[Linear], x: Tensor<2>) -> Option<Tensor<2>> {
        mlp_forward(layers, x, self.negative_slope)
    }

    /// `U (x - mu)`.
    ///
    /// # Shapes
    /// - centred: `[batch, 540 * 90 * 90]` -> `[batch, K]`
    pub fn coefficients(&self, centred: Tensor<2>) -> Tensor<2> {
        centred.matmul(self.basis().transpose()) // [batch, K]
    }

    /// `z = c[..k] + f(c)`.
    ///
    /// # Shapes
    /// - coefficients: `[batch, K]` -> `[batch, k]`
    pub fn encode(&self, coefficients: Tensor<2>) -> Tensor<2> {
        let batch = coefficients.dims()[0];
        let head = coefficients.clone().slice([0..batch, 0..self.latent]); // [batch, k]
        match self.mlp(&self.encoder, coefficients) {
            Some(f) => head + f, // [batch, k]
            None => head,
        }
    }

    /// `c_hat = [z, 0] + g(z)`.
    ///
    /// # Shapes
    /// - latent: `[batch, k]` -> `[batch, K]`
    pub fn decode(&self, latent: Tensor<2>) -> Tensor<2> {
        let batch = latent.dims()[0];
        let padded = if self.size > self.latent {
            let zeros = Tensor::zeros([batch, self.size - self.latent], &latent.device());
            Tensor::cat(vec![latent.clone(), zeros], 1) // [batch, K]
        } else {
            latent.clone()
        };
        match self.mlp(&self.decoder, latent) {
            Some(g) => padded + g, // [batch, K]
            None => padded,
        }
    }

    /// `U^T c_hat`.
    ///
    /// # Shapes
    /// - coefficients: `[batch, K]` -> `[batch, 540 * 90 * 90]`
    pub fn expand(&self, coefficients: Tensor<2>) -> Tensor<2> {
        coefficients.matmul(self.basis()) // [batch, 540*90*90]
    }
}

/// Three linear layers `from -> hidden -> hidden -> to`, the hidden ones from `init`, the last
/// at zero (none without `hidden`): the MLPs of the spectral and slice networks.
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

fn taken() -> ModelError {
    ModelError::Invalid("this spectral path's basis was already taken".into())
}

//! A `slice` model's reconstruction stage by stage (docs/model.md): where a defect of a decoded
//! table enters. Each stage is a whole MERL table, from the input's own masked mapped layout
//! (eq. 1, §3.2):
//!
//! - **basis**: the layout projected onto the slice basis, `B^T B x`: the best any latent can
//!   give, the basis' own truncation;
//! - **linear**: the principal-component path alone, `B^T (m + P[..k]^T c[..k])`: PCA in the
//!   mapped space within the basis' span at the model's k;
//! - **encoded**: the decoder (MLPs included) at the encoder's latent, unrefined;
//! - **refined**: the model's own encoding ([`DeepBrdf::reconstruct`], refined through the
//!   decoder as the model is set to, [`crate::refine`]).

use burn::prelude::*;
use burn::tensor::TensorData;
use deepbrdf_data::layout::from_layout;
use deepbrdf_data::network_input::mapped_layout;
use deepbrdf_data::MerlTable;

use crate::autoencoder::{INPUT_CHANNELS, INPUT_SIDE};
use crate::codec::DeepBrdf;
use crate::error::{ModelError, Result};

/// The stages of [`stages`], in order.
pub const STAGES: [&str; 4] = ["basis", "linear", "encoded", "refined"];

/// One material's tables at each of [`STAGES`].
pub struct Stages {
    pub basis: MerlTable,
    pub linear: MerlTable,
    pub encoded: MerlTable,
    pub refined: MerlTable,
}

impl Stages {
    /// The tables in [`STAGES`] order.
    pub fn tables(&self) -> [&MerlTable; 4] {
        [&self.basis, &self.linear, &self.encoded, &self.refined]
    }
}

/// `table` through `model` stage by stage. Fails for a model that is not a `slice` network.
pub fn stages(model: &DeepBrdf, table: &MerlTable) -> Result<Stages> {
    let net = model
        .network()
        .slice()
        .ok_or_else(|| ModelError::Invalid("stages are defined for a `slice` model only".into()))?;
    let (mut input, mask) = mapped_layout(table, model.reference());
    for (v, m) in input.iter_mut().zip(&mask) {
        *v *= m;
    }
    let device = model.device();
    let shape = [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE];
    let masked = Tensor::from_data(TensorData::new(input, shape), device);
    let a = net.coefficients(masked); // [1, 540 M]
    let unmap = |layout: Tensor<4>, what: &str| -> Result<MerlTable> {
        let values = crate::read_back::values(layout, what)?;
        Ok(model.reference().unmap(&from_layout(&values), model.grid_mask())?)
    };
    let basis = unmap(net.expand(a.clone()), "the basis projection")?;
    let linear = unmap(
        net.expand(net.decode_linear(net.linear_latent(a.clone()))),
        "the linear reconstruction",
    )?;
    let encoded = crate::read_back::values(net.encode_coefficients(a), "the latent vector")?;
    let encoded = model.decode(&encoded)?;
    let refined = model.reconstruct(table)?;
    Ok(Stages { basis, linear, encoded, refined })
}

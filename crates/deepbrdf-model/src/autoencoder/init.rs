//! The initializers the networks draw their weights from.

use burn::nn::Initializer;

/// The initializers of hidden layers (each followed by a leaky ReLU of slope `negative_slope`)
/// and of linear outputs: He initialisation (normal, gain sqrt(2 / (1 + slope^2))) with
/// `he_init`, else PyTorch's default (uniform, gain 1/sqrt(3)).
pub(crate) fn initializers(he_init: bool, negative_slope: f64) -> (Initializer, Initializer) {
    if he_init {
        let gain = (2.0 / (1.0 + negative_slope * negative_slope)).sqrt();
        (
            Initializer::KaimingNormal { gain, fan_out_only: false },
            Initializer::KaimingNormal { gain: 1.0, fan_out_only: false },
        )
    } else {
        let default = Initializer::KaimingUniform { gain: 1.0 / 3f64.sqrt(), fan_out_only: false };
        (default.clone(), default)
    }
}

//! One Neural BRDF network (Sztrajman et al., "Neural BRDF Representation and Importance
//! Sampling", CGF 40(6), 2021): a 6 -> 21 -> 21 -> 3 multilayer perceptron fitted to one measured
//! material. Its input is the Rusinkiewicz half vector (rotated to phi_h = 0) and difference
//! vector; its output is RGB reflectance in 1/sr:
//!
//! `h1 = relu(W1 x + b1)`, `h2 = relu(W2 h1 + b2)`, `rgb = exp(W3 h2 + b3) - 1`,
//!
//! with `x = (sin th, 0, cos th, sin td cos pd, sin td sin pd, cos td)` and each weight matrix
//! stored row per output neuron (out x in).

use crate::error::{DataError, Result};
use serde::Deserialize;
use std::path::Path;

/// Inputs of the network: the half vector and the difference vector.
pub const INPUTS: usize = 6;
/// Width of both hidden layers.
pub const HIDDEN: usize = 21;
/// Outputs of the network: RGB.
pub const OUTPUTS: usize = 3;
/// `(in, out)` of the three layers, in order.
pub const LAYER_SHAPES: [(usize, usize); 3] =
    [(INPUTS, HIDDEN), (HIDDEN, HIDDEN), (HIDDEN, OUTPUTS)];
/// Number of parameters (weights and biases) of one network: 675.
pub const PARAMETERS: usize =
    INPUTS * HIDDEN + HIDDEN + HIDDEN * HIDDEN + HIDDEN + HIDDEN * OUTPUTS + OUTPUTS;

/// A network's weights in f32 (as the original Keras models were trained).
#[derive(Clone, PartialEq)]
pub struct Network {
    name: String,
    /// Layer 1 weights, `w1[out][in]`.
    pub(crate) w1: [[f32; INPUTS]; HIDDEN],
    pub(crate) b1: [f32; HIDDEN],
    pub(crate) w2: [[f32; HIDDEN]; HIDDEN],
    pub(crate) b2: [f32; HIDDEN],
    pub(crate) w3: [[f32; HIDDEN]; OUTPUTS],
    pub(crate) b3: [f32; OUTPUTS],
}

impl std::fmt::Debug for Network {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Network {{ name: {:?}, {INPUTS}->{HIDDEN}->{HIDDEN}->{OUTPUTS} }}", self.name)
    }
}

/// The JSON file layout: `{"name", "collection", "layers": [{"in", "out", "weight", "bias"}]}`.
#[derive(Deserialize)]
struct JsonNetwork {
    name: String,
    layers: Vec<JsonLayer>,
}

#[derive(Deserialize)]
struct JsonLayer {
    #[serde(rename = "in")]
    inputs: usize,
    #[serde(rename = "out")]
    outputs: usize,
    weight: Vec<Vec<f64>>,
    bias: Vec<f64>,
}

/// The input vector `x = (h, d)` of the cell at angles (radians) `theta_h`, `theta_d`, `phi_d`:
/// `h = (sin th, 0, cos th)`, `d = (sin td cos pd, sin td sin pd, cos td)`.
pub fn input_vector(theta_h: f64, theta_d: f64, phi_d: f64) -> [f64; INPUTS] {
    let (sh, ch) = theta_h.sin_cos();
    let (sd, cd) = theta_d.sin_cos();
    let (sp, cp) = phi_d.sin_cos();
    [sh, 0.0, ch, sd * cp, sd * sp, cd]
}

impl Network {
    /// Builds a network from its flat parameters in the bundle order: W1 (row per output), b1,
    /// W2, b2, W3, b3. Rejects the wrong count and non-finite values.
    pub fn from_parameters(name: impl Into<String>, params: &[f32]) -> Result<Self> {
        let name = name.into();
        if params.len() != PARAMETERS {
            return Err(DataError::Invalid(format!(
                "network {name}: expected {PARAMETERS} parameters, got {}",
                params.len()
            )));
        }
        if let Some(i) = params.iter().position(|v| !v.is_finite()) {
            return Err(DataError::Invalid(format!(
                "network {name}: parameter {i} is {} (not finite)",
                params[i]
            )));
        }
        let mut it = params.iter().copied();
        let mut next = || it.next().unwrap_or(0.0);
        let mut net = Self {
            name,
            w1: [[0.0; INPUTS]; HIDDEN],
            b1: [0.0; HIDDEN],
            w2: [[0.0; HIDDEN]; HIDDEN],
            b2: [0.0; HIDDEN],
            w3: [[0.0; HIDDEN]; OUTPUTS],
            b3: [0.0; OUTPUTS],
        };
        net.w1.iter_mut().flatten().for_each(|w| *w = next());
        net.b1.iter_mut().for_each(|w| *w = next());
        net.w2.iter_mut().flatten().for_each(|w| *w = next());
        net.b2.iter_mut().for_each(|w| *w = next());
        net.w3.iter_mut().flatten().for_each(|w| *w = next());
        net.b3.iter_mut().for_each(|w| *w = next());
        Ok(net)
    }

    /// The flat parameters, in the order [`Network::from_parameters`] reads.
    pub fn parameters(&self) -> Vec<f32> {
        let mut p = Vec::with_capacity(PARAMETERS);
        p.extend(self.w1.iter().flatten());
        p.extend(&self.b1);
        p.extend(self.w2.iter().flatten());
        p.extend(&self.b2);
        p.extend(self.w3.iter().flatten());
        p.extend(&self.b3);
        p
    }

    /// The parameters as little-endian f32 bytes: what the cache key and the bundle hash.
    pub fn parameter_bytes(&self) -> Vec<u8> {
        self.parameters().iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    /// The material's name (e.g. `chrome`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Reads a JSON network file, checking every shape strictly.
    pub fn read_json(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, e))?;
        if meta.is_dir() {
            return Err(DataError::format(path, "is a directory, not a JSON network file"));
        }
        // A 6-21-21-3 network takes about 14 kB of JSON; refuse absurd sizes before reading.
        const MAX_JSON_BYTES: u64 = 1 << 20;
        if meta.len() > MAX_JSON_BYTES {
            return Err(DataError::format(
                path,
                format!(
                    "{} bytes is too large for a NBRDF network (at most {MAX_JSON_BYTES})",
                    meta.len()
                ),
            ));
        }
        let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
        Self::from_json(&bytes).map_err(|problem| DataError::format(path, problem))
    }

    /// Parses a JSON network from memory; the error is a description of the problem.
    pub fn from_json(bytes: &[u8]) -> std::result::Result<Self, String> {
        let json: JsonNetwork =
            serde_json::from_slice(bytes).map_err(|e| format!("not a NBRDF network: {e}"))?;
        if json.layers.len() != LAYER_SHAPES.len() {
            return Err(format!(
                "expected {} layers (6->21->21->3), found {}",
                LAYER_SHAPES.len(),
                json.layers.len()
            ));
        }
        let mut params = Vec::with_capacity(PARAMETERS);
        for (l, (layer, &(inputs, outputs))) in json.layers.iter().zip(&LAYER_SHAPES).enumerate() {
            let l = l + 1;
            if layer.inputs != inputs || layer.outputs != outputs {
                return Err(format!(
                    "layer {l} is {}->{}, expected {inputs}->{outputs}",
                    layer.inputs, layer.outputs
                ));
            }
            if layer.weight.len() != outputs {
                return Err(format!(
                    "layer {l} weight has {} rows, expected {outputs} (one per output)",
                    layer.weight.len()
                ));
            }
            for (r, row) in layer.weight.iter().enumerate() {
                if row.len() != inputs {
                    return Err(format!(
                        "layer {l} weight row {r} has {} entries, expected {inputs}",
                        row.len()
                    ));
                }
            }
            if layer.bias.len() != outputs {
                return Err(format!(
                    "layer {l} bias has {} entries, expected {outputs}",
                    layer.bias.len()
                ));
            }
            for (what, values) in [("weight", layer.weight.concat()), ("bias", layer.bias.clone())]
            {
                for v in values {
                    let f = v as f32;
                    if !f.is_finite() {
                        return Err(format!("layer {l} {what} holds {v}, not a finite f32"));
                    }
                    params.push(f);
                }
            }
        }
        // The loop pushed weights then bias per layer: the bundle order.
        Self::from_parameters(json.name, &params).map_err(|e| e.to_string())
    }

    /// Evaluates the network on an input vector in f64 (exact reference arithmetic on the f32
    /// weights): RGB reflectance in 1/sr, not clamped (a poor fit can dip slightly below 0).
    pub fn evaluate_input(&self, x: &[f64; INPUTS]) -> [f64; OUTPUTS] {
        let mut h1 = [0.0f64; HIDDEN];
        for (o, h) in h1.iter_mut().enumerate() {
            let s: f64 = self.w1[o].iter().zip(x).map(|(&w, &v)| w as f64 * v).sum();
            *h = (s + self.b1[o] as f64).max(0.0);
        }
        let mut h2 = [0.0f64; HIDDEN];
        for (o, h) in h2.iter_mut().enumerate() {
            let s: f64 = self.w2[o].iter().zip(&h1).map(|(&w, &v)| w as f64 * v).sum();
            *h = (s + self.b2[o] as f64).max(0.0);
        }
        let mut rgb = [0.0f64; OUTPUTS];
        for (o, c) in rgb.iter_mut().enumerate() {
            let s: f64 = self.w3[o].iter().zip(&h2).map(|(&w, &v)| w as f64 * v).sum();
            *c = (s + self.b3[o] as f64).exp_m1();
        }
        rgb
    }

    /// Evaluates the network at Rusinkiewicz angles (radians): RGB reflectance in 1/sr.
    pub fn evaluate(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> [f64; OUTPUTS] {
        self.evaluate_input(&input_vector(theta_h, theta_d, phi_d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(inputs: usize, outputs: usize) -> serde_json::Value {
        serde_json::json!({
            "in": inputs, "out": outputs,
            "weight": vec![vec![0.01; inputs]; outputs],
            "bias": vec![0.0; outputs],
        })
    }

    fn json(layers: Vec<serde_json::Value>) -> Vec<u8> {
        serde_json::to_vec(
            &serde_json::json!({"name": "t", "collection": "merl", "layers": layers}),
        )
        .unwrap_or_default()
    }

    #[test]
    fn parameters_round_trip() {
        let params: Vec<f32> = (0..PARAMETERS).map(|i| i as f32 * 0.001 - 0.3).collect();
        let net = Network::from_parameters("x", &params).expect("valid");
        assert_eq!(net.parameters(), params);
        assert_eq!(net.w1[1][0], params[INPUTS]);
        assert_eq!(net.b1[0], params[INPUTS * HIDDEN]);
        assert_eq!(*net.b3.last().unwrap_or(&0.0), params[PARAMETERS - 1]);
    }

    #[test]
    fn well_formed_json_parses_and_zero_output_layer_gives_zero() {
        let bytes = json(vec![layer(6, 21), layer(21, 21), layer(21, 3)]);
        let mut net = Network::from_json(&bytes).expect("valid");
        net.w3 = [[0.0; HIDDEN]; OUTPUTS];
        // exp(0) - 1 = 0 whatever the hidden layers do.
        assert_eq!(net.evaluate(0.3, 0.2, 0.1), [0.0; 3]);
    }

    #[test]
    fn wrong_shapes_are_rejected_with_the_problem() {
        let cases: Vec<(Vec<serde_json::Value>, &str)> = vec![
            (vec![layer(6, 21), layer(21, 21)], "expected 3 layers"),
            (vec![layer(6, 20), layer(20, 21), layer(21, 3)], "layer 1 is 6->20"),
            (vec![layer(6, 21), layer(21, 21), layer(21, 4)], "layer 3 is 21->4"),
        ];
        for (layers, needle) in cases {
            let err = Network::from_json(&json(layers)).expect_err("must fail");
            assert!(err.contains(needle), "{err} lacks {needle}");
        }
        let mut bad_row = layer(21, 21);
        bad_row["weight"][3] = serde_json::json!(vec![0.0; 20]);
        let err = Network::from_json(&json(vec![layer(6, 21), bad_row, layer(21, 3)]))
            .expect_err("must fail");
        assert!(err.contains("layer 2 weight row 3 has 20 entries"), "{err}");
        let mut bad_bias = layer(21, 3);
        bad_bias["bias"] = serde_json::json!([0.0, 1.0]);
        let err = Network::from_json(&json(vec![layer(6, 21), layer(21, 21), bad_bias]))
            .expect_err("must fail");
        assert!(err.contains("layer 3 bias has 2 entries"), "{err}");
        let mut huge = layer(6, 21);
        huge["weight"][0][0] = serde_json::json!(1e300);
        let err = Network::from_json(&json(vec![huge, layer(21, 21), layer(21, 3)]))
            .expect_err("must fail");
        assert!(err.contains("not a finite f32"), "{err}");
        assert!(Network::from_json(b"{\"name\": 3}").is_err());
    }

    #[test]
    fn input_vector_is_half_and_difference_vector() {
        // theta_h = 0: h is the normal; d spherical at (theta_d, phi_d).
        let x = input_vector(0.0, 0.3, 0.5);
        let expect =
            [0.0, 0.0, 1.0, 0.3f64.sin() * 0.5f64.cos(), 0.3f64.sin() * 0.5f64.sin(), 0.3f64.cos()];
        for (a, b) in x.iter().zip(expect) {
            assert!((a - b).abs() < 1e-15);
        }
    }
}

//! Where the shipped default model lives: `models/default/` at the repository root, the
//! training directory of `experiments train --preset slice` (the autoencoder artifact in
//! `model/`, its log and configuration), with the networks trained for it beside it
//! (`regressor/` for §5.1 editing, `recovery/` for §5.2 single-image recovery). The command line
//! and the Python package both default to it.

/// The shipped default model's directory, as built into this crate (the checkout it was
/// compiled from).
pub const DEFAULT_MODEL_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/default");

/// Name of the folder holding a model's regressors (eq. 7), inside the model directory.
pub const REGRESSOR_DIR: &str = "regressor";

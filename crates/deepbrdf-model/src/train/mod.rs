//! Training: one loop for every network ([`run`], with the network-specific [`TrainStep`]) and
//! its parts, one file each: the settings ([`config`]), the learning-rate schedule
//! ([`schedule`]), epoch order and batching ([`order`]), checkpoints and exact resume
//! ([`checkpoint`]), the NaN stop (`divergence`), the CSV log ([`log`]) and progress
//! (`progress`). Each network family trains through it from its own folder: the autoencoder in
//! [`crate::autoencoder::train`], the regressor in [`crate::regressor::training`], the recovery
//! CNN in [`crate::recovery::step`].
//!
//! A network is trained by implementing [`TrainStep`] (build it, and the loss and gradients
//! of a batch of example indices) and calling [`run`] with a [`LoopConfig`], the run's
//! configuration as JSON (compared on resume), a fingerprint of the data and a [`Session`].

pub mod checkpoint;
pub mod config;
mod divergence;
pub mod log;
pub mod order;
mod progress;
pub mod run;
pub mod schedule;

pub use checkpoint::{checkpoint_path, json_close, saved_log, CHECKPOINT_FILE, CONFIG_FILE};
pub use config::{adam, LoopConfig};
pub use log::{EpochRecord, LOG_FILE};
pub use order::epoch_order;
pub use run::{on_device, run, Outcome, Session, TrainStep};

#[cfg(test)]
mod tests;

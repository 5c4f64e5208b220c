//! Figures of results: line charts (error vs k, per-material error) as SVG and PNG, and the
//! picture of Fig. 2 (phi_d slices of a BRDF and of its reconstructions, [`slices`]).
mod plots;
pub mod slices;

pub use plots::{write_chart, write_panels, LineChart, Series};

//! Figures of results: line charts (error vs k, per-material error) as compact SVG
//! ([`compact`]), and the picture of Fig. 2 (phi_d slices of a BRDF and of its reconstructions,
//! [`slices`]).
pub mod compact;
mod plots;
pub mod slices;

pub use compact::compact_svg;
pub use plots::{write_chart, write_panels, LineChart, Series};

//! Figures of results: line charts (error vs k, per-material error) as SVG and PNG.
mod plots;

pub use plots::{write_chart, write_panels, LineChart, Series};

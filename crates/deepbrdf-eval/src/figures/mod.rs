//! Figures of results: line charts (error vs k, per-material error) as compact SVG
//! ([`compact`]), the picture of Fig. 2 (phi_d slices of a BRDF and of its reconstructions,
//! [`slices`]), and Fig. 5's latent plane ([`latent_plane`]) drawn as a scatter plot of
//! materials ([`scatter`]).
pub mod compact;
pub mod latent_map;
pub mod latent_plane;
mod plots;
pub mod reconstruction_sheet;
pub mod scatter;
pub mod schedules;
pub mod slices;
pub mod strip;

pub use compact::compact_svg;
pub use latent_map::{LatentMap, LatentMapInput};
pub use latent_plane::LatentPlane;
pub use plots::{write_chart, write_panels, write_panels_png, LineChart, Series};
pub use reconstruction_sheet::{ReconstructionSheet, SheetInput};
pub use scatter::{draw_scatter, ScatterPlot, ScatterPoint};
pub use strip::{figure_caption, strip};

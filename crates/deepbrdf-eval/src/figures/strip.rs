//! A strip of renders: one row per sequence of tables (an interpolation path, an edit sweep),
//! captioned, each table rendered at the figure's settings with its own importance sampling,
//! and the renderer's noise there for the caption.

use crate::error::{EvalError, Result};
use crate::metrics::ImageRelae;
use crate::metrics::ImageRelaeConfig;
use deepbrdf_data::MerlTable;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::{Srgb8Image, Tonemap};

/// The strip of `rows` (tiles `captions(row, column)`) and the renderer's noise: the image
/// RelAE between two seeds' renders of the first tile.
pub fn strip(
    rows: &[&[MerlTable]],
    captions: &dyn Fn(usize, usize) -> String,
    figure: &ImageRelaeConfig,
) -> Result<(Srgb8Image, f64)> {
    let tonemap = Tonemap { exposure: 1.0 };
    let mut tiles = Vec::new();
    let mut noise = None;
    for (row, tables) in rows.iter().enumerate() {
        for (i, table) in tables.iter().enumerate() {
            let tile = ImageRelae::new(table, figure)?;
            if noise.is_none() {
                noise = Some(tile.noise(table)?);
            }
            let image = tile.reference().to_srgb8(&tonemap, [24, 24, 24]);
            tiles.push(Tile { image, caption: captions(row, i) });
        }
    }
    let noise = noise.ok_or_else(|| EvalError::Invalid("a strip of no tables".into()))?;
    let columns = rows.first().map(|r| r.len()).unwrap_or(1) as u32;
    let config = SheetConfig { columns, ..SheetConfig::default() };
    Ok((contact_sheet(&tiles, &config)?, noise))
}

/// How a figure's tiles were rendered, and their noise, for its caption.
pub fn figure_caption(figure: &ImageRelaeConfig, noise: f64) -> String {
    let r = &figure.render;
    format!(
        "{} px tiles, {} Sobol samples per pixel, seed {}; render noise (image RelAE between two seeds' renders of the first tile) {noise:.4}.",
        r.size, r.spp, r.seed
    )
}

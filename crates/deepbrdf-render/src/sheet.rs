//! Contact sheets for figures: a grid of renders, each with a caption under it. Captions are
//! drawn with plotters in DejaVu Sans, embedded in the binary (the `dejavu` crate), so sheets
//! look the same on machines without fonts.

use super::image::Srgb8Image;
use crate::error::{RenderError, Result};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::sync::OnceLock;

/// Layout of a contact sheet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetConfig {
    /// Tiles per row (0: about square, `ceil(sqrt(n))`).
    pub columns: u32,
    /// Height of the caption band under each tile, pixels.
    pub caption_height: u32,
    /// Largest caption font size, pixels (smaller for long captions, down to 7 px).
    pub font_px: u32,
    /// Gap between tiles, pixels.
    pub gap: u32,
    pub background: [u8; 3],
    pub text: [u8; 3],
}

impl Default for SheetConfig {
    fn default() -> Self {
        Self {
            columns: 0,
            caption_height: 16,
            font_px: 12,
            gap: 4,
            background: [24, 24, 24],
            text: [230, 230, 230],
        }
    }
}

/// One tile: an image and its caption.
#[derive(Clone, Debug)]
pub struct Tile {
    pub image: Srgb8Image,
    pub caption: String,
}

/// Smallest caption font size.
const MIN_FONT_PX: u32 = 7;

/// Registers the embedded DejaVu Sans as plotters' `sans-serif` (once per process), for the
/// captions here and the charts of `deepbrdf-eval`: no figure depends on the system's fonts.
pub fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(RenderError::Invalid("the embedded DejaVu Sans font could not be loaded".into()))
    }
}

/// Lays `tiles` out in a grid (all tiles the size of the first) with captions.
pub fn contact_sheet(tiles: &[Tile], config: &SheetConfig) -> Result<Srgb8Image> {
    let first = tiles
        .first()
        .ok_or_else(|| RenderError::Invalid("a contact sheet needs at least one tile".into()))?;
    let (tw, th) = (first.image.width, first.image.height);
    if let Some(t) = tiles.iter().find(|t| (t.image.width, t.image.height) != (tw, th)) {
        return Err(RenderError::Invalid(format!(
            "tile '{}' is {}x{}, the first is {tw}x{th}",
            t.caption, t.image.width, t.image.height
        )));
    }
    register_font()?;
    let n = tiles.len() as u32;
    let columns = if config.columns > 0 {
        config.columns.min(n)
    } else {
        (f64::from(n).sqrt().ceil() as u32).max(1)
    };
    let rows = n.div_ceil(columns);
    let (cell_w, cell_h) = (tw + config.gap, th + config.caption_height + config.gap);
    let (width, height) = (columns * cell_w + config.gap, rows * cell_h + config.gap);
    if u64::from(width) * u64::from(height) > 1 << 28 {
        return Err(RenderError::Invalid(format!(
            "contact sheet of {width}x{height} pixels is too large"
        )));
    }
    let mut sheet = Srgb8Image::filled(width, height, config.background);
    let origin =
        |i: u32| (config.gap + (i % columns) * cell_w, config.gap + (i / columns) * cell_h);
    for (i, tile) in tiles.iter().enumerate() {
        let (x, y) = origin(i as u32);
        sheet.blit(&tile.image, x, y);
    }
    {
        let root = BitMapBackend::with_buffer(&mut sheet.data, (width, height)).into_drawing_area();
        let colour = RGBColor(config.text[0], config.text[1], config.text[2]);
        let draw_err = |e: String| RenderError::Invalid(format!("drawing captions: {e}"));
        for (i, tile) in tiles.iter().enumerate() {
            let (x, y) = origin(i as u32);
            let (text, size) =
                fit_caption(&root, &tile.caption, config.font_px, tw.saturating_sub(2))
                    .map_err(|e| draw_err(e.to_string()))?;
            let style = TextStyle::from(("sans-serif", size as f64).into_font())
                .color(&colour)
                .pos(Pos::new(HPos::Center, VPos::Center));
            let centre = ((x + tw / 2) as i32, (y + th + config.caption_height / 2) as i32);
            root.draw_text(&text, &style, centre).map_err(|e| draw_err(e.to_string()))?;
        }
        root.present().map_err(|e| draw_err(e.to_string()))?;
    }
    Ok(sheet)
}

/// The caption and font size that fit in `max_width` pixels: the largest size from `font_px`
/// down to [`MIN_FONT_PX`]; at the smallest, the text is cut and ends in an ellipsis.
fn fit_caption<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    font_px: u32,
    max_width: u32,
) -> std::result::Result<(String, u32), DrawingAreaErrorKind<DB::ErrorType>> {
    let width =
        |text: &str, size: u32| -> std::result::Result<u32, DrawingAreaErrorKind<DB::ErrorType>> {
            let style = TextStyle::from(("sans-serif", size as f64).into_font());
            Ok(root.estimate_text_size(text, &style)?.0)
        };
    let top = font_px.max(MIN_FONT_PX);
    for size in (MIN_FONT_PX..=top).rev() {
        if width(caption, size)? <= max_width {
            return Ok((caption.to_string(), size));
        }
    }
    let mut chars: Vec<char> = caption.chars().collect();
    while !chars.is_empty() {
        chars.pop();
        let text: String = chars.iter().collect::<String>() + "…";
        if width(&text, MIN_FONT_PX)? <= max_width {
            return Ok((text, MIN_FONT_PX));
        }
    }
    Ok((String::new(), MIN_FONT_PX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_land_in_the_grid_with_captions_below() {
        let tiles: Vec<Tile> = (0..5u8)
            .map(|i| Tile {
                image: Srgb8Image::filled(20, 10, [50 * i, 100, 200]),
                caption: format!("material-number-{i}-with-a-long-name"),
            })
            .collect();
        let cfg = SheetConfig { columns: 3, caption_height: 12, gap: 2, ..Default::default() };
        let sheet = contact_sheet(&tiles, &cfg).unwrap();
        // 3 columns x 2 rows of 22 x 24 cells, plus the outer gap.
        assert_eq!((sheet.width, sheet.height), (3 * 22 + 2, 2 * 24 + 2));
        let px = |x: u32, y: u32| {
            let i = 3 * (y * sheet.width + x) as usize;
            [sheet.data[i], sheet.data[i + 1], sheet.data[i + 2]]
        };
        // Tile 4 is at column 1, row 1: (2 + 22, 2 + 24).
        assert_eq!(px(24 + 5, 26 + 5), [200, 100, 200]);
        assert_eq!(px(0, 0), cfg.background);
        // Some caption pixels were drawn (brighter than the background) under tile 0.
        let caption_lit = (2..22)
            .flat_map(|x| (12..24).map(move |y| (x, y)))
            .filter(|&(x, y)| px(x, y)[0] > 100)
            .count();
        assert!(caption_lit > 5, "{caption_lit}");
    }

    #[test]
    fn rejects_mixed_sizes_and_no_tiles() {
        assert!(contact_sheet(&[], &SheetConfig::default()).is_err());
        let a = Tile { image: Srgb8Image::filled(4, 4, [0; 3]), caption: "a".into() };
        let b = Tile { image: Srgb8Image::filled(5, 4, [0; 3]), caption: "b".into() };
        assert!(contact_sheet(&[a, b], &SheetConfig::default()).is_err());
    }
}

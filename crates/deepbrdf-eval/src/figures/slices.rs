//! The picture of Fig. 2 (Hu et al., CGF 2020): a few phi_d slices of one BRDF as images
//! (rows theta_h, columns theta_d, eq. (1) mapped values in false colour): the original, and
//! DeepBRDF's reconstructions from all, 1/3 and 1/9 of the slices.

use crate::deep::NAME;
use crate::error::{EvalError, Result};
use deepbrdf_data::augment::{kept_slices, SliceSelection};
use deepbrdf_data::merl::{cell_index, CELLS, N_THETA_D, N_THETA_H};
use deepbrdf_data::MerlTable;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::image::false_colour;
use deepbrdf_render::{contact_sheet, SheetConfig, Srgb8Image, Tile};
use std::path::Path;

/// The BRDF the paper shows in Fig. 2.
pub const FIG2_MATERIAL: &str = "specular-violet-phenolic";

/// The phi_d slices shown (degrees = index, MERL's phi_d step is 1 degree).
pub const SLICES: [usize; 4] = [0, 45, 90, 135];

/// Pixels per table cell in the picture.
const SCALE: u32 = 2;

/// Colour of invalid (below the horizon) cells.
const INVALID_COLOUR: [u8; 3] = [60, 60, 60];

/// Writes the Fig. 2 picture of `table` reconstructed by `model` to `path`
/// (PNG): one row per input (original, all, 1/3, 1/9 of the slices), one column per slice of
/// [`SLICES`]. All tiles share one colour scale: 0 to the 99.5th percentile of the original's
/// mapped values, which is returned.
pub fn write(model: &DeepBrdf, table: &MerlTable, path: &Path) -> Result<f32> {
    let reference = model.reference();
    let mask = table.mask();
    let mut rows: Vec<(String, Vec<f32>)> = vec![("original".into(), reference.map(table))];
    for every in [1, 3, 9] {
        let recon = match every {
            1 => model.encode(table),
            _ => model.encode_partial(table, &kept_slices(&SliceSelection::Every(every), 0)),
        }
        .and_then(|latent| model.decode(&latent))
        .map_err(|e| EvalError::method(format!("{NAME}-{}", model.k()), e))?;
        let label = if every == 1 { "from all".to_string() } else { format!("from 1/{every}") };
        rows.push((format!("k={} {label}", model.k()), reference.map(&recon)));
    }
    let scale = colour_scale(&rows[0].1, &mask);
    let mut tiles = Vec::new();
    for (label, mapped) in &rows {
        for &p in &SLICES {
            tiles.push(Tile {
                image: slice_image(mapped, &mask, p, scale),
                caption: format!("{label}, φd {p}°"),
            });
        }
    }
    let config =
        SheetConfig { columns: SLICES.len() as u32, caption_height: 18, ..SheetConfig::default() };
    contact_sheet(&tiles, &config)?.write_png(path)?;
    Ok(scale)
}

/// The upper end of the colour scale: the 99.5th percentile of the valid mapped values (so a
/// few extreme specular cells do not wash everything else out).
fn colour_scale(mapped: &[f32], mask: &[bool]) -> f32 {
    let mut v: Vec<f32> = (0..3)
        .flat_map(|c| (0..CELLS).filter(|&cell| mask[cell]).map(move |cell| c * CELLS + cell))
        .map(|i| mapped[i])
        .filter(|v| v.is_finite())
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    let at = ((v.len() - 1) as f64 * 0.995) as usize;
    let (_, &mut top, _) = v.select_nth_unstable_by(at, f32::total_cmp);
    if top > 0.0 {
        top
    } else {
        1.0
    }
}

/// One phi_d slice as a false-colour image: the mean of the three channels' mapped values.
fn slice_image(mapped: &[f32], mask: &[bool], phi_d: usize, scale: f32) -> Srgb8Image {
    let (w, h) = (N_THETA_D as u32 * SCALE, N_THETA_H as u32 * SCALE);
    let mut img = Srgb8Image::filled(w, h, INVALID_COLOUR);
    for y in 0..h {
        for x in 0..w {
            let cell = cell_index((y / SCALE) as usize, (x / SCALE) as usize, phi_d);
            if !mask[cell] {
                continue;
            }
            let v = (0..3).map(|c| mapped[c * CELLS + cell]).sum::<f32>() / 3.0;
            let rgb = false_colour(v / scale);
            let i = 3 * (y * w + x) as usize;
            img.data[i..i + 3].copy_from_slice(&rgb);
        }
    }
    img
}

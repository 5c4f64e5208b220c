//! The reconstruction figures of Hu et al. (2020): a few materials rendered as measured and as
//! each representation reconstructs them, the image RelAE of each reconstruction under its
//! tile ([`ImageRelae`] on the preview sphere under sun and sky): Fig. 4 (§3.3: the L2 and L1
//! models), Fig. 6 (§4: DeepBRDF, PCA and IPCA at several k), Figs. 8 and 9 (§4.2: DeepBRDF
//! against Sun et al. 2018 and IPCA). The
//! renderer's noise is measured beside it: the RelAE between two renders of each measurement
//! with different seeds (an upper bound: a reconstruction is rendered with the measurement's
//! seed and sampling, so most noise cancels in its RelAE).

use crate::error::Result;
use crate::harness::Codec;
use crate::metrics::{relae, ImageRelae, ImageRelaeConfig};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::{Srgb8Image, Tonemap};

/// What a sheet shows.
pub struct SheetInput<'a> {
    /// The materials, by name (the originals' captions), with their tables.
    pub names: &'a [&'a str],
    pub tables: &'a [&'a MerlTable],
    /// The representations, each with its label.
    pub methods: &'a [(&'a str, &'a dyn Codec)],
    pub config: &'a ImageRelaeConfig,
    /// The colour the renders' background is composited over.
    pub background: [u8; 3],
    /// A reconstruction's caption from its method's label, k and image RelAE.
    pub caption: &'a dyn Fn(&str, usize, f64) -> String,
}

/// One representation's reconstructions: the image RelAE of each material and its tiles.
pub struct Column {
    pub label: String,
    pub k: usize,
    pub relae: Vec<f64>,
    tiles: Vec<Tile>,
}

/// The figure's content: the measurements' tiles and render noise, and a column per method.
pub struct ReconstructionSheet {
    originals: Vec<Tile>,
    pub noise: Vec<f64>,
    pub columns: Vec<Column>,
}

/// A reconstruction's caption naming its method and image RelAE (Figs. 4, 8 and 9).
pub fn relae_caption(label: &str, _k: usize, relae: f64) -> String {
    format!("{label}: RelAE {relae:.3}")
}

/// A reconstruction's caption naming its method, k and image RelAE (Fig. 6).
pub fn relae_caption_with_k(label: &str, k: usize, relae: f64) -> String {
    format!("{label} {k}D: RelAE {relae:.3}")
}

/// The sheet's layout for `columns` tiles a row: captions larger than the default, for
/// 256-px tiles.
pub fn sheet_config(columns: u32) -> SheetConfig {
    SheetConfig { columns, caption_height: 22, font_px: 15, ..SheetConfig::default() }
}

impl ReconstructionSheet {
    /// Renders each measurement and measures the noise, then encodes, decodes and renders each
    /// material by each method.
    pub fn measure(input: &SheetInput, progress: &dyn Progress) -> Result<Self> {
        let n = input.tables.len();
        let srgb =
            |img: &deepbrdf_render::Image| img.to_srgb8(&Tonemap::default(), input.background);
        progress.start((n * (input.methods.len() + 2)) as u64, "rendering the figure");
        let (mut measures, mut noise, mut originals) = (vec![], vec![], vec![]);
        for (table, name) in input.tables.iter().zip(input.names) {
            let measure = ImageRelae::new(table, input.config)?;
            progress.advance(1);
            noise.push(measure.noise(table)?);
            progress.advance(1);
            originals.push(Tile { image: srgb(measure.reference()), caption: name.to_string() });
            measures.push(measure);
        }
        let mut columns = Vec::with_capacity(input.methods.len());
        for &(label, codec) in input.methods {
            let k = codec.k();
            let mut c = Column { label: label.into(), k, relae: vec![], tiles: vec![] };
            for (table, measure) in input.tables.iter().zip(&measures) {
                let image = measure.render(&codec.decode(&codec.encode(table)?)?)?;
                let e = relae(&image, measure.reference())?;
                c.relae.push(e);
                c.tiles.push(Tile { image: srgb(&image), caption: (input.caption)(label, k, e) });
                progress.advance(1);
            }
            columns.push(c);
        }
        progress.finish();
        Ok(Self { originals, noise, columns })
    }

    /// A row per material of `rows` (indices into the input's materials): the measurement,
    /// then each method's reconstruction (Figs. 4 and 6).
    pub fn by_material(&self, rows: &[usize]) -> Result<Srgb8Image> {
        let mut tiles = Vec::new();
        for &s in rows {
            tiles.push(self.originals[s].clone());
            tiles.extend(self.columns.iter().map(|c| c.tiles[s].clone()));
        }
        Ok(contact_sheet(&tiles, &sheet_config(1 + self.columns.len() as u32))?)
    }

    /// A row of measurements, then a row per method (Figs. 8 and 9).
    pub fn by_method(&self) -> Result<Srgb8Image> {
        let mut tiles = self.originals.clone();
        for c in &self.columns {
            tiles.extend(c.tiles.iter().cloned());
        }
        Ok(contact_sheet(&tiles, &sheet_config(self.originals.len() as u32))?)
    }
}

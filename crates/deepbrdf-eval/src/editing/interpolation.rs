//! Interpolation between two materials (Hu et al. 2020, §5.1, Fig. 10) along three paths: the
//! DeepBRDF latent `(1 - t) z_A + t z_B`, IPCA coefficients at the same k, and a plain linear
//! blend of the two tables as the reference; each path's uniformity (the coefficient of
//! variation of the image RelAE between consecutive steps) and plausibility.

use crate::editing::ModelCodec;
use crate::editing::{blend, blend_tables, coefficient_of_variation, path_weights, plausibility};
use crate::error::Result;
use crate::harness::Codec;
use crate::metrics::{relae, ImageRelae, ImageRelaeConfig};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::Image;

/// One interpolation path: its name, tables and renders.
pub struct InterpolationPath {
    pub name: String,
    pub tables: Vec<MerlTable>,
    pub images: Vec<Image>,
}

impl InterpolationPath {
    /// RelAE between consecutive renders.
    pub fn steps(&self) -> Result<Vec<f64>> {
        self.images.windows(2).map(|w| relae(&w[1], &w[0])).collect()
    }
}

/// Renders `tables` with `reference`'s scene and sampling (shared noise along a path).
pub fn render_all(reference: &ImageRelae, tables: &[MerlTable]) -> Result<Vec<Image>> {
    tables.iter().map(|t| reference.render(t)).collect()
}

/// The paths from `a` to `b` in `steps` steps, both ends included: DeepBRDF's, IPCA's where
/// `ipca` is given, and the linear blend; renders with `a`'s sampling at the measures'
/// settings.
pub fn paths(
    model: &DeepBrdf,
    ipca: Option<&dyn Codec>,
    a: &MerlTable,
    b: &MerlTable,
    steps: usize,
    progress: &dyn Progress,
) -> Result<Vec<InterpolationPath>> {
    let reference = ImageRelae::new(a, &ImageRelaeConfig::default())?;
    let ts = path_weights(steps);
    let deep = ModelCodec(model);
    let mut codecs: Vec<&dyn Codec> = vec![&deep];
    codecs.extend(ipca);
    let mut out = Vec::new();
    progress.start((steps * (codecs.len() + 1)) as u64, "interpolating");
    for (codec, name) in codecs.iter().zip(["DeepBRDF", "IPCA"]) {
        let (za, zb) = (codec.encode(a)?, codec.encode(b)?);
        let mut tables = Vec::new();
        for &t in &ts {
            tables.push(codec.decode(&blend(&za, &zb, t))?);
            progress.advance(1);
        }
        let images = render_all(&reference, &tables)?;
        out.push(InterpolationPath { name: name.into(), tables, images });
    }
    let mut tables = Vec::new();
    for &t in &ts {
        tables.push(blend_tables(a, b, t)?);
        progress.advance(1);
    }
    let images = render_all(&reference, &tables)?;
    out.push(InterpolationPath { name: "linear blend".into(), tables, images });
    progress.finish();
    Ok(out)
}

/// A markdown table of the paths' uniformity and plausibility.
pub fn summary(paths: &[InterpolationPath]) -> Result<String> {
    let mut s = String::from(
        "| path | CV of consecutive image RelAE | mean step RelAE | negative values | max directional albedo |\n| --- | ---: | ---: | ---: | ---: |\n",
    );
    for p in paths {
        let steps = p.steps()?;
        let mean = steps.iter().sum::<f64>() / steps.len() as f64;
        let checks: Vec<_> = p.tables.iter().map(plausibility).collect();
        let negative: usize = checks.iter().map(|c| c.negative_values).sum();
        let albedo = checks.iter().map(|c| c.max_albedo).fold(f64::NEG_INFINITY, f64::max);
        s += &format!(
            "| {} | {:.3} | {:.4} | {negative} | {albedo:.3} |\n",
            p.name,
            coefficient_of_variation(&steps),
            mean
        );
    }
    Ok(s)
}

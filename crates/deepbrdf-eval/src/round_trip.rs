//! The round trip of a real measurement through the project's formats: an RGL measurement
//! (Dupuy & Jakob 2018) converted to the MERL grid, written back as an RGL file by
//! [`deepbrdf_data::rgl::export`] and evaluated by the project's RGL evaluator, against the
//! original measurement's own evaluator. The MERL table's own image error (the conversion
//! alone) is the yardstick: an export should add little to it.
//!
//! Every image is rendered with the MERL table's sampling and the same seed, so the same
//! directions are drawn and a difference is the materials', not Monte Carlo noise (as
//! `experiments compare` does).

use crate::error::Result;
use crate::metrics::compare_images;
use deepbrdf_data::rgl::{export, ExportResolution, RglBrdf};
use deepbrdf_data::MerlTable;
use deepbrdf_data::Progress;
use deepbrdf_render::brdf::MeasuredBrdf;
use deepbrdf_render::{render, MerlBrdf, RenderSettings, Scene, Tonemap};

/// The scene every image of a round trip is rendered in.
pub struct Stage<'a> {
    pub scene: &'a Scene,
    pub settings: &'a RenderSettings,
    pub tonemap: &'a Tonemap,
}

/// The image errors of one measurement's round trip.
#[derive(Clone, Debug, PartialEq)]
pub struct RoundTrip {
    /// Image RelAE of the MERL table against the measurement.
    pub table_relae: f64,
    /// Image RelAE of each exported file (at each resolution asked for) against the
    /// measurement.
    pub export_relae: Vec<f64>,
}

/// Renders `measured` (named `name`), its MERL table `table` and the table exported at each of
/// `resolutions`, and measures each against the measurement.
pub fn round_trip(
    name: &str,
    measured: &RglBrdf,
    table: &MerlTable,
    resolutions: &[ExportResolution],
    stage: &Stage,
    progress: &dyn Progress,
) -> Result<RoundTrip> {
    let sampling = MerlBrdf::new(table);
    let evaluator = |brdf: &RglBrdf| {
        let brdf = MeasuredBrdf { brdf, sampling: &sampling };
        render(stage.scene, &brdf, stage.settings, progress)
    };
    let original = evaluator(measured)?;
    let relae =
        |image| -> Result<f64> { Ok(compare_images(&image, &original, stage.tonemap)?.relae) };
    let table_relae = relae(render(stage.scene, &sampling, stage.settings, progress)?)?;
    let export_relae = resolutions
        .iter()
        .map(|resolution| {
            let file = export(table, name, resolution, format!("<export of {name}>"))?;
            relae(evaluator(&RglBrdf::from_tensor(&file)?)?)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(RoundTrip { table_relae, export_relae })
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::rgl::{bundled, tabulate};
    use deepbrdf_render::{SceneConfig, Tonemap};

    #[test]
    fn a_finer_export_of_a_measurement_comes_closer_to_it() -> Result<()> {
        let measured = bundled::load("paper_white_rgb")?;
        let table = tabulate(&measured)?;
        let scene = SceneConfig::default().build()?;
        let settings = RenderSettings { size: 24, spp: 4, ..RenderSettings::default() };
        let tonemap = Tonemap::default();
        let stage = Stage { scene: &scene, settings: &settings, tonemap: &tonemap };
        let coarse = ExportResolution { theta_i: 4, ndf: 32, vndf: 32, rgb: 8 };
        let fine = ExportResolution { theta_i: 16, ndf: 128, vndf: 64, rgb: 32 };
        let r = round_trip(
            "paper",
            &measured,
            &table,
            &[coarse, fine],
            &stage,
            &deepbrdf_data::Silent,
        )?;
        assert!(r.table_relae < 0.01, "{r:?}");
        assert!(r.export_relae[1] < r.export_relae[0], "{r:?}");
        Ok(())
    }
}

//! `figures-recovery`'s measurement: every usable image of a test set recovered by the four
//! methods and scored in a novel scene against the truth, and the few kept for the figures.
use super::Args;
use crate::recovery_inputs::{load_tables, set_images};
use anyhow::bail;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::harness::{Measure, Yardstick};
use deepbrdf_eval::metrics::{relae, ImageRelae, ImageRelaeConfig};
use deepbrdf_eval::recovery::{attributes_from_targets, nearest_materials, novel_scene};
use deepbrdf_model::recovery::RecoveryArtifact;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::{
    camera_png, Photo, RenderSet, RenderSettings, Sampler, Shape, Srgb8Image, Tonemap,
};
use std::collections::BTreeMap;
use std::path::Path;

/// One image's results.
pub(super) struct Row {
    pub(super) set: String,
    pub(super) index: usize,
    pub(super) material: String,
    pub(super) shape: &'static str,
    pub(super) relae: [f64; 4],
    pub(super) mse: [f64; 4],
    pub(super) nearest: String,
}

/// Figure material kept for a few images.
pub(super) struct Shown {
    pub(super) input: Srgb8Image,
    pub(super) truth: Srgb8Image,
    pub(super) recovered: [Srgb8Image; 2],
    /// Image RelAE of the two recovered renders against the truth's, at the figure settings.
    pub(super) relae: [f64; 2],
    /// The renderer's noise at the figure settings: the truth rendered with two seeds.
    pub(super) noise: f64,
    pub(super) material: String,
}

/// Renders `truth` and the `recovered` tables in `config`'s scene for a figure, developed by
/// `develop`.
fn figure_tiles(
    truth: &MerlTable,
    recovered: [&MerlTable; 2],
    config: &ImageRelaeConfig,
    develop: &dyn Fn(&deepbrdf_render::Image) -> Srgb8Image,
    input: Srgb8Image,
    material: &str,
) -> anyhow::Result<Shown> {
    let measure = ImageRelae::new(truth, config)?;
    let [a, b] = recovered.map(|t| measure.render(t));
    let (a, b) = (a?, b?);
    Ok(Shown {
        relae: [relae(&a, measure.reference())?, relae(&b, measure.reference())?],
        noise: measure.noise(truth)?,
        input,
        truth: develop(measure.reference()),
        recovered: [develop(&a), develop(&b)],
        material: material.to_string(),
    })
}

/// What every test set is measured against: the networks, the training materials (the
/// nearest-neighbour candidates and the training mean) and the yardstick of the mapped MSE.
pub(super) struct Bench<'a> {
    pub(super) args: &'a Args,
    pub(super) device: &'a deepbrdf_model::burn::tensor::Device,
    pub(super) model: &'a DeepBrdf,
    pub(super) network: &'a RecoveryArtifact,
    pub(super) analytic: &'a RecoveryArtifact,
    pub(super) train: &'a RenderSet,
    pub(super) train_tables: &'a BTreeMap<String, MerlTable>,
    pub(super) mean: &'a MerlTable,
    pub(super) yardstick: &'a Yardstick,
    pub(super) cache: &'a deepbrdf_data::cache::Cache,
}

/// The results gathered over the test sets: a row per image, the images skipped per set
/// (name, unusable, all) and the figures' tiles.
#[derive(Default)]
pub(super) struct Found {
    pub(super) rows: Vec<Row>,
    pub(super) skipped: Vec<(String, usize, usize)>,
    pub(super) shown: Vec<Shown>,
    pub(super) planes: Vec<Shown>,
}

/// What the methods recover from a test set's usable images (`indices` into the set), in their
/// order: DeepBRDF's latents, the analytic network's attributes and the nearest training
/// material.
struct Recovered {
    indices: Vec<usize>,
    latents: Vec<Vec<f32>>,
    attributes: Vec<Vec<f32>>,
    nearest: Vec<String>,
}

/// The test set whose Figs. 16 and 17 are drawn.
const FIGURE_SET: &str = "held-out";

impl Bench<'_> {
    /// Recovers every usable image of the test set `name` in `dir` by the four methods and
    /// measures each against the truth; keeps a few for the figures.
    pub(super) fn measure(
        &self,
        name: &str,
        dir: &Path,
        found: &mut Found,
        progress: &dyn Progress,
    ) -> anyhow::Result<()> {
        let set = RenderSet::load(dir)?;
        let overlap: Vec<&String> = set
            .header
            .materials
            .iter()
            .filter(|m| self.train.header.materials.contains(m))
            .collect();
        if !overlap.is_empty() {
            bail!(
                "{}: {} of its materials (e.g. {}) are in the training set; not held out",
                dir.display(),
                overlap.len(),
                overlap[0]
            );
        }
        let truth = load_tables(&set.header.materials, self.cache, progress)?;
        let recovered = self.recover(&set, dir, name, found, progress)?;
        progress.start(recovered.indices.len() as u64, &format!("measuring {name}"));
        for j in 0..recovered.indices.len() {
            self.score(name, &set, dir, &truth, &recovered, j, found)?;
            progress.advance(1);
        }
        progress.finish();
        Ok(())
    }

    /// The set's usable images (the unusable ones counted in `found.skipped`) and what each
    /// method makes of them.
    fn recover(
        &self,
        set: &RenderSet,
        dir: &Path,
        name: &str,
        found: &mut Found,
        progress: &dyn Progress,
    ) -> anyhow::Result<Recovered> {
        let (network, analytic, device) = (self.network, self.analytic, self.device);
        let indices: Vec<usize> = (0..set.images.len()).collect();
        let side = network.config().input_side;
        let usable = set_images(set, dir, &indices, side, progress)?;
        if let Some(note) = usable.note(dir) {
            eprintln!("{note}");
        }
        found.skipped.push((name.to_string(), usable.unusable.len(), indices.len()));
        let inputs = &usable.pixels;
        let latents = network.predictor(device)?.predict(inputs)?;
        let side7 = analytic.config().input_side;
        let attributes = if side7 == side {
            analytic.predictor(device)?.predict(inputs)?
        } else {
            let again = set_images(set, dir, &usable.indices, side7, progress)?;
            if again.indices != usable.indices {
                bail!(
                    "{}: the analytic network's input side makes other images unusable",
                    dir.display()
                );
            }
            analytic.predictor(device)?.predict(&again.pixels)?
        };
        let nearest = nearest_materials(
            set,
            &usable.indices,
            inputs,
            side,
            self.train_tables,
            self.args.nn_spp,
            progress,
        )?;
        Ok(Recovered { indices: usable.indices, latents, attributes, nearest })
    }

    /// Image `j` of `recovered`: the four recoveries' image RelAE in a novel scene and mapped
    /// MSE against the truth, a row of `found`; the figures' tiles where it is kept for them.
    #[allow(clippy::too_many_arguments)]
    fn score(
        &self,
        name: &str,
        set: &RenderSet,
        dir: &Path,
        truth: &BTreeMap<String, MerlTable>,
        recovered: &Recovered,
        j: usize,
        found: &mut Found,
    ) -> anyhow::Result<()> {
        let (args, yardstick) = (self.args, self.yardstick);
        let i = recovered.indices[j];
        let image = &set.images[i];
        let t = &truth[&image.material];
        let decoded = self.model.decode(&recovered.latents[j])?;
        let fitted = attributes_from_targets(&recovered.attributes[j])?.table();
        let near = &self.train_tables[&recovered.nearest[j]];
        let recon: [&MerlTable; 4] = [&decoded, &fitted, near, self.mean];
        // The independent sampler, as the image RelAE default (the committed numbers).
        let cfg = ImageRelaeConfig {
            scene: novel_scene(set, i),
            render: RenderSettings {
                size: args.size,
                spp: args.spp,
                seed: 0x5eed,
                jitter: true,
                sampler: Sampler::Independent,
            },
        };
        let relae_of = ImageRelae::new(t, &cfg)?;
        let original = yardstick.original(t);
        let mut relae = [0.0; 4];
        let mut mse = [0.0; 4];
        for (m, r) in recon.iter().enumerate() {
            relae[m] = relae_of.measure(r)?;
            mse[m] = yardstick.measure(&original, r, &[Measure::MappedMse])?[0];
        }
        if name == FIGURE_SET {
            self.keep_for_figures(set, dir, i, t, [&decoded, &fitted], found)?;
        }
        found.rows.push(Row {
            set: name.to_string(),
            index: i,
            material: image.material.clone(),
            shape: image.scene.scene.shape.name(),
            relae,
            mse,
            nearest: recovered.nearest[j].clone(),
        });
        Ok(())
    }

    /// Fig. 16's tiles for the first six materials seen on a shape other than a plane (the
    /// truth and the recoveries in the novel scene), Fig. 17's for the first four planes (the
    /// input's own scene, re-rendered with each table).
    fn keep_for_figures(
        &self,
        set: &RenderSet,
        dir: &Path,
        i: usize,
        truth: &MerlTable,
        recovered: [&MerlTable; 2],
        found: &mut Found,
    ) -> anyhow::Result<()> {
        let image = &set.images[i];
        let figure = ImageRelaeConfig::figure(self.args.figure_size, self.args.figure_spp, 0);
        let input_png = || Photo::read(&set.paths(dir, i).0).map(|p| p.to_srgb8());
        let is_plane = matches!(image.scene.scene.shape, Shape::Plane { .. });
        let Found { shown, planes, .. } = found;
        if !is_plane && shown.len() < 6 && !shown.iter().any(|s| s.material == image.material) {
            let tm = Tonemap::default();
            let config = ImageRelaeConfig { scene: novel_scene(set, i), ..figure };
            let develop = |img: &deepbrdf_render::Image| img.to_srgb8(&tm, [0, 0, 0]);
            let input = input_png()?;
            shown.push(figure_tiles(truth, recovered, &config, &develop, input, &image.material)?);
        }
        if is_plane && planes.len() < 4 {
            let config = ImageRelaeConfig { scene: image.scene.scene, ..figure };
            let develop =
                |img: &deepbrdf_render::Image| camera_png(img, image.scene.exposure, 0.0, 0);
            let input = input_png()?;
            planes.push(figure_tiles(truth, recovered, &config, &develop, input, &image.material)?);
        }
        Ok(())
    }
}

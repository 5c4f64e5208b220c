//! `experiments figures-recovery`: single-image recovery (§5.2) measured against its baselines,
//! with Fig. 16 (input / ground truth / recovered) and Fig. 17 (planes: DeepBRDF against the
//! analytic fit), written under `results/recovery/`.
//!
//! Every image of a test set (rendered with `render-set --only-fold`, so its materials are held
//! out of the training set, the CNN and, when the model was trained without them, the
//! autoencoder; or a set of another collection, for generalization) is recovered by four
//! methods: DeepBRDF (the CNN's latent, decoded), the analytic baseline (the same CNN with 7
//! outputs, Lambertian + GGX), the nearest neighbour (the training material whose render in the
//! input's own scene is closest to the input) and the training mean (the per-value mean of the
//! training materials). Each recovered table and the true one are rendered in a *novel* scene
//! (another shape, view and sky than the input's: the input view alone rewards copying its
//! highlights) and compared by image RelAE; the mapped-space (eq. 1) MSE of the tables is
//! reported beside it. The figures re-render the shown tables at `--figure-size` and
//! `--figure-spp` (Sobol points) and state the renderer's noise there; the input column is the
//! image as the network sees it.
use crate::args::data::CacheArg;
use crate::args::model::ModelArg;
use crate::recovery_inputs::{load_tables, set_images};
use anyhow::{bail, Context};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::figures::{write_chart, LineChart, Series};
use deepbrdf_eval::harness::{Measure, Yardstick};
use deepbrdf_eval::metrics::{relae, ImageRelae, ImageRelaeConfig};
use deepbrdf_eval::recovery::{
    attributes_from_targets, mean_table, nearest_materials, novel_scene,
};
use deepbrdf_eval::stats::{finite_mean, finite_median};
use deepbrdf_model::recovery::{RecoveryArtifact, RecoveryTarget};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::{
    camera_png, Photo, RenderSet, RenderSettings, Sampler, Shape, Srgb8Image, Tonemap,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The methods, in table order.
const METHODS: [&str; 4] = ["deepbrdf", "analytic", "nearest", "mean"];

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub network: crate::args::network::NetworkArg,
    /// The analytic baseline: a recovery network trained with `--target attributes`.
    #[arg(long, value_name = "DIR")]
    pub analytic: PathBuf,
    /// The render set the networks were trained on (its materials are the nearest-neighbour
    /// candidates and make the training mean).
    #[arg(long, value_name = "DIR")]
    pub train_set: PathBuf,
    /// Held-out test set (`render-set --only-fold`), the table's first block.
    #[arg(long, value_name = "DIR")]
    pub test_set: PathBuf,
    /// Further test sets of materials never trained on (generalization), NAME=DIR.
    #[arg(long, value_name = "NAME=DIR")]
    pub generalize: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/recovery")]
    pub out: PathBuf,
    /// Side and samples per pixel of the novel-scene renders.
    #[arg(long, default_value_t = 64)]
    pub size: u32,
    #[arg(long, default_value_t = 32)]
    pub spp: u32,
    /// Samples per pixel of the nearest-neighbour search's renders (every training material in
    /// every input's scene: the costly part).
    #[arg(long, default_value_t = 4)]
    pub nn_spp: u32,
    /// Side of the figures' rendered tiles (Figs. 16 and 17; the inputs are shown at their own
    /// side, enlarged).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(16..=1024))]
    pub figure_size: u32,
    /// Samples per pixel of the figures' renders (Sobol points).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub figure_spp: u32,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// One image's results.
struct Row {
    set: String,
    index: usize,
    material: String,
    shape: &'static str,
    relae: [f64; 4],
    mse: [f64; 4],
    nearest: String,
}

/// Figure material kept for a few images.
struct Shown {
    input: Srgb8Image,
    truth: Srgb8Image,
    recovered: [Srgb8Image; 2],
    /// Image RelAE of the two recovered renders against the truth's, at the figure settings.
    relae: [f64; 2],
    /// The renderer's noise at the figure settings: the truth rendered with two seeds.
    noise: f64,
    material: String,
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

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let model_dir = args.model.dir()?;
    let model = DeepBrdf::load(&model_dir, &device)?;
    let network = args.network.load(&model_dir, &model)?;
    let analytic = RecoveryArtifact::load(&args.analytic)?;
    if analytic.target() != &RecoveryTarget::Attributes {
        bail!(
            "{}: not an attributes network (train it with --target attributes)",
            args.analytic.display()
        );
    }
    let cache = args.cache.cache();
    let train = RenderSet::load(&args.train_set)?;
    let train_tables = load_tables(&train.header.materials, &cache, progress)?;
    let mean = mean_table(train_tables.values().collect::<Vec<_>>().as_slice())?;
    let yardstick = Yardstick::from_reference(model.reference().clone());

    let mut sets = vec![("held-out".to_string(), args.test_set.clone())];
    for g in &args.generalize {
        let (name, dir) =
            g.split_once('=').with_context(|| format!("--generalize '{g}': expected NAME=DIR"))?;
        sets.push((name.to_string(), PathBuf::from(dir)));
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let bench = Bench {
        args: &args,
        device: &device,
        model: &model,
        network: &network,
        analytic: &analytic,
        train: &train,
        train_tables: &train_tables,
        mean: &mean,
        yardstick: &yardstick,
        cache: &cache,
    };
    let mut found = Found::default();
    for (name, dir) in &sets {
        bench.measure(name, dir, &mut found, progress)?;
    }
    let Found { rows, skipped, shown, planes } = &found;
    write_outputs(&args, rows, skipped, shown, planes, &model, &network, &analytic)
}

/// What every test set is measured against: the networks, the training materials (the
/// nearest-neighbour candidates and the training mean) and the yardstick of the mapped MSE.
struct Bench<'a> {
    args: &'a Args,
    device: &'a deepbrdf_model::burn::tensor::Device,
    model: &'a DeepBrdf,
    network: &'a RecoveryArtifact,
    analytic: &'a RecoveryArtifact,
    train: &'a RenderSet,
    train_tables: &'a std::collections::BTreeMap<String, MerlTable>,
    mean: &'a MerlTable,
    yardstick: &'a Yardstick,
    cache: &'a deepbrdf_data::cache::Cache,
}

/// The results gathered over the test sets: a row per image, the images skipped per set
/// (name, unusable, all) and the figures' tiles.
#[derive(Default)]
struct Found {
    rows: Vec<Row>,
    skipped: Vec<(String, usize, usize)>,
    shown: Vec<Shown>,
    planes: Vec<Shown>,
}

impl Bench<'_> {
    /// Recovers every usable image of the test set `name` in `dir` by the four methods and
    /// measures each against the truth; keeps a few for the figures.
    fn measure(
        &self,
        name: &str,
        dir: &Path,
        found: &mut Found,
        progress: &dyn Progress,
    ) -> anyhow::Result<()> {
        let (args, device) = (self.args, self.device);
        let (model, network, analytic) = (self.model, self.network, self.analytic);
        let (train_tables, mean, yardstick) = (self.train_tables, self.mean, self.yardstick);
        let Found { rows, skipped, shown, planes } = found;
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
        let indices: Vec<usize> = (0..set.images.len()).collect();
        let side = network.config().input_side;
        let usable = set_images(&set, dir, &indices, side, progress)?;
        if let Some(note) = usable.note(dir) {
            eprintln!("{note}");
        }
        skipped.push((name.to_string(), usable.unusable.len(), indices.len()));
        let inputs = &usable.pixels;
        let latents = network.predictor(device)?.predict(inputs)?;
        let side7 = analytic.config().input_side;
        let attributes = if side7 == side {
            analytic.predictor(device)?.predict(inputs)?
        } else {
            let again = set_images(&set, dir, &usable.indices, side7, progress)?;
            if again.indices != usable.indices {
                bail!(
                    "{}: the analytic network's input side makes other images unusable",
                    dir.display()
                );
            }
            analytic.predictor(device)?.predict(&again.pixels)?
        };
        let nearest = nearest_materials(
            &set,
            &usable.indices,
            inputs,
            side,
            train_tables,
            args.nn_spp,
            progress,
        )?;
        progress.start(usable.indices.len() as u64, &format!("measuring {name}"));
        for (j, &i) in usable.indices.iter().enumerate() {
            let image = &set.images[i];
            let t = &truth[&image.material];
            let decoded = model.decode(&latents[j])?;
            let fitted = attributes_from_targets(&attributes[j])?.table();
            let near = &train_tables[&nearest[j]];
            let recon: [&MerlTable; 4] = [&decoded, &fitted, near, &mean];
            // The independent sampler, as the image RelAE default (the committed numbers).
            let cfg = ImageRelaeConfig {
                scene: novel_scene(&set, i),
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
            let is_plane = matches!(image.scene.scene.shape, Shape::Plane { .. });
            let input_png = || Photo::read(&set.paths(dir, i).0).map(|p| p.to_srgb8());
            if name == "held-out"
                && !is_plane
                && shown.len() < 6
                && !shown.iter().any(|s| s.material == image.material)
            {
                let tm = Tonemap::default();
                let config = ImageRelaeConfig {
                    scene: novel_scene(&set, i),
                    ..ImageRelaeConfig::figure(args.figure_size, args.figure_spp, 0)
                };
                shown.push(figure_tiles(
                    t,
                    [&decoded, &fitted],
                    &config,
                    &|img| img.to_srgb8(&tm, [0, 0, 0]),
                    input_png()?,
                    &image.material,
                )?);
            }
            if name == "held-out" && is_plane && planes.len() < 4 {
                // Fig. 17: the plane of the input itself, re-rendered with each table.
                let config = ImageRelaeConfig {
                    scene: image.scene.scene,
                    ..ImageRelaeConfig::figure(args.figure_size, args.figure_spp, 0)
                };
                planes.push(figure_tiles(
                    t,
                    [&decoded, &fitted],
                    &config,
                    &|img| camera_png(img, image.scene.exposure, 0.0, 0),
                    input_png()?,
                    &image.material,
                )?);
            }
            rows.push(Row {
                set: name.to_string(),
                index: i,
                material: image.material.clone(),
                shape: image.scene.scene.shape.name(),
                relae,
                mse,
                nearest: nearest[j].clone(),
            });
            progress.advance(1);
        }
        progress.finish();
        Ok(())
    }
}

#[allow(clippy::too_many_arguments)]
fn write_outputs(
    args: &Args,
    rows: &[Row],
    skipped: &[(String, usize, usize)],
    shown: &[Shown],
    planes: &[Shown],
    model: &DeepBrdf,
    network: &RecoveryArtifact,
    analytic: &RecoveryArtifact,
) -> anyhow::Result<()> {
    let mut csv = String::from("set,index,material,shape,nearest");
    for m in METHODS {
        write!(csv, ",relae_{m}")?;
    }
    for m in METHODS {
        write!(csv, ",mapped_mse_{m}")?;
    }
    csv.push('\n');
    for r in rows {
        write!(csv, "{},{},{},{},{}", r.set, r.index, r.material, r.shape, r.nearest)?;
        for v in r.relae.iter().chain(&r.mse) {
            write!(csv, ",{v:.6}")?;
        }
        csv.push('\n');
    }
    deepbrdf_data::files::write_atomic(&args.out.join("per_image.csv"), csv.as_bytes())?;

    let mut md = String::new();
    writeln!(md, "Single-image recovery (§5.2), written by `experiments figures-recovery` (see the README's Recovery section for the full command).")?;
    writeln!(md)?;
    writeln!(
        md,
        "DeepBRDF model {} (k = {}); recovery CNN {} ({} images, {} epochs); analytic CNN {}.",
        model.id(),
        model.k(),
        network.id(),
        network.provenance().images,
        network.provenance().epochs,
        analytic.id()
    )?;
    writeln!(md, "Novel-scene renders: {0}x{0} px, {1} spp. RelAE: image space, novel shape, view and sky; MSE: mapped space (eq. 1), the model's reference.", args.size, args.spp)?;
    for (set, n, of) in skipped.iter().filter(|s| s.1 > 0) {
        writeln!(md, "{set}: {n} of {of} images skipped as unusable (the checks `recover` applies to a photo: no object, no dark background, saturated).")?;
    }
    writeln!(md)?;
    writeln!(md, "| test set | images | materials | method | RelAE mean | RelAE median | mapped MSE mean | best RelAE on |")?;
    writeln!(md, "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: |")?;
    let mut sets: Vec<&str> = rows.iter().map(|r| r.set.as_str()).collect();
    sets.dedup();
    for set in &sets {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.set == *set).collect();
        let mut materials: Vec<&str> = rs.iter().map(|r| r.material.as_str()).collect();
        materials.sort();
        materials.dedup();
        for (m, method) in METHODS.iter().enumerate() {
            let wins = rs.iter().filter(|r| (0..4).all(|o| r.relae[m] <= r.relae[o])).count();
            writeln!(
                md,
                "| {set} | {} | {} | {method} | {:.4} | {:.4} | {:.4} | {wins} |",
                rs.len(),
                materials.len(),
                finite_mean(rs.iter().map(|r| r.relae[m])),
                finite_median(rs.iter().map(|r| r.relae[m])),
                finite_mean(rs.iter().map(|r| r.mse[m])),
            )?;
        }
    }
    for set in &sets {
        writeln!(md)?;
        writeln!(md, "![{set}, per material](per_material_{set}.svg)")?;
        per_material_chart(rows, set, &args.out.join(format!("per_material_{set}")))?;
    }
    if !shown.is_empty() || !planes.is_empty() {
        let noise = shown.iter().chain(planes).map(|s| s.noise).fold(0.0, f64::max);
        writeln!(md)?;
        writeln!(
            md,
            "Fig. 16 (`fig16.jpg`: held-out inputs as the network sees them, enlarged; the truth \
             and DeepBRDF's recovery rendered in the novel scene) and Fig. 17 (`fig17.jpg`: \
             held-out planes, the truth, DeepBRDF and the analytic baseline re-rendered in the \
             input's own scene): {0} px, {1} spp, Sobol points, seed 0; the RelAE under a tile \
             is at these settings. Render noise (the truth rendered with seeds 0 and 1): at \
             most {noise:.4}.",
            args.figure_size, args.figure_spp
        )?;
        writeln!(md)?;
        writeln!(md, "![Fig. 16](fig16.jpg)")?;
        writeln!(md)?;
        writeln!(md, "![Fig. 17](fig17.jpg)")?;
    }
    deepbrdf_data::files::write_atomic(&args.out.join("summary.md"), md.as_bytes())?;
    print!("{md}");

    let short = |m: &str| m.rsplit('/').next().unwrap_or(m).to_string();
    let up = |img: &Srgb8Image| img.upscaled((args.figure_size / img.width.max(1)).max(1));
    let sheet_config = |columns: usize| SheetConfig {
        columns: columns as u32,
        caption_height: 22,
        font_px: 15,
        ..Default::default()
    };
    if !shown.is_empty() {
        let mut tiles = Vec::new();
        for row in 0..3 {
            for s in shown {
                let (image, caption) = match row {
                    0 => (up(&s.input), short(&s.material)),
                    1 => (s.truth.clone(), "ground truth".to_string()),
                    _ => (s.recovered[0].clone(), format!("DeepBRDF: RelAE {:.3}", s.relae[0])),
                };
                tiles.push(Tile { image, caption });
            }
        }
        contact_sheet(&tiles, &sheet_config(shown.len()))?
            .write_figure(&args.out.join("fig16.jpg"))?;
    }
    if !planes.is_empty() {
        let mut tiles = Vec::new();
        for row in 0..4 {
            for s in planes {
                let (image, caption) = match row {
                    0 => (up(&s.input), format!("{} (input)", short(&s.material))),
                    1 => (s.truth.clone(), "ground truth".to_string()),
                    2 => (s.recovered[0].clone(), format!("DeepBRDF: RelAE {:.3}", s.relae[0])),
                    _ => (s.recovered[1].clone(), format!("analytic: RelAE {:.3}", s.relae[1])),
                };
                tiles.push(Tile { image, caption });
            }
        }
        contact_sheet(&tiles, &sheet_config(planes.len()))?
            .write_figure(&args.out.join("fig17.jpg"))?;
    }
    eprintln!(
        "wrote {}/summary.md, per_image.csv, per_material_*.svg, fig16.jpg, fig17.jpg",
        args.out.display()
    );
    Ok(())
}

/// The novel-scene RelAE of each method per material of test set `set` (the mean over the
/// material's images), materials sorted by the methods' geometric mean, as `<stem>.svg`.
fn per_material_chart(rows: &[Row], set: &str, stem: &std::path::Path) -> anyhow::Result<()> {
    let rs: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
    let mut materials: Vec<&str> = rs.iter().map(|r| r.material.as_str()).collect();
    materials.sort();
    materials.dedup();
    let value = |material: &str, m: usize| {
        finite_mean(rs.iter().filter(|r| r.material == material).map(|r| r.relae[m]))
    };
    let key =
        |material: &str| (0..METHODS.len()).map(|m| value(material, m).max(1e-9).ln()).sum::<f64>();
    materials.sort_by(|a, b| key(a).total_cmp(&key(b)));
    let series = METHODS
        .iter()
        .enumerate()
        .map(|(m, method)| Series {
            label: method.to_string(),
            points: materials.iter().enumerate().map(|(x, n)| (x as f64, value(n, m))).collect(),
        })
        .collect();
    let chart = LineChart {
        title: format!("recovery, {set}: image RelAE per material, novel scenes"),
        x_label: "material".into(),
        y_label: "image RelAE".into(),
        log_y: true,
        series,
        categories: Some(
            materials.iter().map(|m| m.rsplit('/').next().unwrap_or(m).to_string()).collect(),
        ),
        rotate_categories: true,
        legend_left: true,
        size: ((300 + 14 * materials.len() as u32).clamp(900, 2600), 520),
    };
    write_chart(&chart, stem)?;
    Ok(())
}

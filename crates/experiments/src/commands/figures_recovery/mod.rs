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
mod measure;
mod outputs;

use crate::args::data::CacheArg;
use crate::args::model::ModelArg;
use crate::recovery_inputs::load_tables;
use anyhow::{bail, Context};
use deepbrdf_data::Progress;
use deepbrdf_eval::harness::Yardstick;
use deepbrdf_eval::recovery::mean_table;
use deepbrdf_model::recovery::{RecoveryArtifact, RecoveryTarget};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::RenderSet;
use measure::{Bench, Found};
use std::path::PathBuf;

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
    outputs::write(&args, &found, &model, &network, &analytic)
}
